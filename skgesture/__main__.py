"""``python -m skgesture``: the command line (see ``skgesture --help``)."""

# SPDX-License-Identifier: BSD-3-Clause

import sys

from skgesture._cli import main

__all__ = ["main"]

if __name__ == "__main__":
    sys.exit(main())
