"""Print pip constraints that pin every declared dependency at its floor.

``make test-min`` installs the package with these constraints, so the test suite
runs against the oldest versions ``pyproject.toml`` claims to support:
``numpy>=1.24`` becomes ``numpy==1.24``. Usage::

    python .ci/floors.py pyproject.toml tests plot safe dask > floors.txt

The arguments after the file are the extras whose requirements are pinned too.
A requirement without a ``>=`` floor is an error: every floor must be testable.
"""

import re
import sys

import tomllib

_REQ = re.compile(
    r"^\s*([A-Za-z0-9_.\-]+)(\[[^\]]*\])?\s*>=\s*([0-9][0-9A-Za-z.]*)\s*$"
)


def floors(pyproject, extras=()):
    """Return ``{name: floor}`` for the dependencies and the given extras."""
    with open(pyproject, "rb") as f:
        project = tomllib.load(f)["project"]
    reqs = list(project["dependencies"])
    optional = project.get("optional-dependencies", {})
    for extra in extras:
        reqs += optional[extra]
    out = {}
    for req in reqs:
        m = _REQ.match(req.split(";")[0])
        if m is None:
            raise SystemExit(f"{pyproject}: {req!r} has no plain '>=' floor to test")
        name, floor = m.group(1).lower(), m.group(3)
        names = [name]
        if name == "dask" and "distributed" in (m.group(2) or ""):
            names.append("distributed")  # released in lockstep with dask
        for name in names:
            if out.setdefault(name, floor) != floor:
                raise SystemExit(f"{pyproject}: two floors for {name}: {floor}")
    return out


if __name__ == "__main__":
    if len(sys.argv) < 2:
        raise SystemExit(__doc__)
    for name, floor in sorted(floors(sys.argv[1], sys.argv[2:]).items()):
        print(f"{name}=={floor}")
