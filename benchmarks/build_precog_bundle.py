"""Rebuild the PRECOG 2016 bundle shipped in ``skgesture/datasets/data/``.

Reads the dataset's ``SeqA_B.csv`` files with :func:`skgesture.datasets.load_precog`
(all validation included), keeps subjects 1-8 by default, and writes the compressed
``precog_2016.npz`` (format in the ``skgesture.datasets._precog`` docstring), then
checks that the bundle reads back to the same sequences within float32 precision.

Usage::

    python benchmarks/build_precog_bundle.py ../shared/data/precog_2016/CSV
"""

# SPDX-License-Identifier: BSD-3-Clause

import argparse
from pathlib import Path

import numpy as np

from skgesture.datasets import load_precog
from skgesture.datasets._precog import BUNDLE_FILE, _read_bundle, _write_bundle

DEFAULT_OUTPUT = (
    Path(__file__).resolve().parents[1]
    / "skgesture"
    / "datasets"
    / "data"
    / BUNDLE_FILE
)
DEFAULT_SUBJECTS = tuple(range(1, 9))  # the 48 files of the shared data copy
FLOAT32_TOLERANCE = 2e-7  # metres: float32 spacing near 3 m is 2.4e-7


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv_folder", type=Path, help="folder of SeqA_B.csv files")
    parser.add_argument("--output", type=Path, default=DEFAULT_OUTPUT)
    parser.add_argument(
        "--subjects", type=int, nargs="+", default=list(DEFAULT_SUBJECTS)
    )
    args = parser.parse_args(argv)
    data = load_precog(args.csv_folder, subjects=args.subjects)
    args.output.parent.mkdir(parents=True, exist_ok=True)
    _write_bundle(data, args.output)
    back = _read_bundle(args.output)
    assert len(back) == len(data.X)
    for (script, subject, X, y), x_ref, y_ref, g, s in zip(
        back, data.X, data.y, data.groups, data.scripts
    ):
        assert (script, subject) == (s, g)
        np.testing.assert_array_equal(y, y_ref)
        np.testing.assert_allclose(X, x_ref, rtol=0, atol=FLOAT32_TOLERANCE)
    size = args.output.stat().st_size
    print(
        f"wrote {args.output} ({size / 1e6:.2f} MB): {len(data.X)} sequences, "
        f"{int(data.n_frames.sum())} frames, subjects "
        f"{sorted(set(data.groups.tolist()))}"
    )


if __name__ == "__main__":
    main()
