"""The public API is documented: listed in docs/api.rst, numpydoc-valid, citable.

* Every name in the ``__all__`` of a public module (a module of ``skgesture``
  without a leading underscore in its path) is listed in ``docs/api.rst``, under
  that module's ``.. currentmodule::`` (or with its full dotted name).
* numpydoc's validator passes on every public class and function and on their
  public methods and properties, for the error codes of ``CHECKED_CODES``;
  known failures are listed, with the code, in ``ALLOWED_FAILURES``.
* Every section that the code and docs cite ("docs/method.md §3.7", "decision
  D12", "docs/design.md §3", and the old "METHOD_SPEC §..." / "DESIGN.md §..."
  spellings, read as their docs/ pages) exists in docs/method.md / docs/design.md.
"""

# SPDX-License-Identifier: BSD-3-Clause

import enum
import importlib
import inspect
import pkgutil
import re
from pathlib import Path

import pytest

import skgesture

numpydoc_validate = pytest.importorskip("numpydoc.validate")

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
API_RST = DOCS / "api.rst"

if not API_RST.is_file():  # e.g. an installed wheel without the repository
    pytest.skip("docs/ is not next to the tests", allow_module_level=True)


def _public_modules():
    names = ["skgesture"]
    for info in pkgutil.walk_packages(skgesture.__path__, "skgesture."):
        if not any(part.startswith("_") for part in info.name.split(".")):
            names.append(info.name)
    return sorted(names)


PUBLIC_MODULES = _public_modules()


def _module_sections(text):
    """``{module: text}`` of each ``.. currentmodule::`` section of api.rst."""
    sections = {}
    parts = re.split(
        r"^\.\. (?:currentmodule|automodule):: *(\S+) *$", text, flags=re.M
    )
    for module, body in zip(parts[1::2], parts[2::2]):
        sections[module] = sections.get(module, "") + body
    return sections


def _listed(name, module, sections, text):
    word = re.compile(rf"(?<![\w.]){re.escape(name)}(?!\w)")
    full = re.compile(rf"(?<![\w.]){re.escape(module)}\.{re.escape(name)}(?!\w)")
    return bool(word.search(sections.get(module, ""))) or bool(full.search(text))


@pytest.mark.parametrize("module_name", PUBLIC_MODULES)
def test_api_reference_lists_every_public_name(module_name):
    module = importlib.import_module(module_name)
    assert hasattr(module, "__all__"), f"{module_name} has no __all__"
    text = API_RST.read_text(encoding="utf-8")
    sections = _module_sections(text)
    missing, broken = [], []
    for name in module.__all__:
        if name == "__version__":
            continue
        try:
            obj = getattr(module, name)
        except (AttributeError, ImportError) as exc:
            broken.append(f"{name} ({exc})")
            continue
        if inspect.ismodule(obj):
            ok = obj.__name__ in sections
        else:
            ok = _listed(name, module_name, sections, text)
        if not ok:
            missing.append(name)
    assert not broken, f"{module_name}.__all__ names that do not import: {broken}"
    assert not missing, (
        f"docs/api.rst does not list these names of {module_name}.__all__ "
        f"(add them under '.. currentmodule:: {module_name}'): {missing}"
    )


# --------------------------------------------------------------------------------
# numpydoc validation

# Every numpydoc code is checked except these, for the reasons given:
# ES01 extended summary: optional; a one-line method needs none.
# SA01 "See Also": optional; the estimators have one, helpers need none.
# RT02 "Returns" names the value: we follow scikit-learn's ``self : object``.
# GL01 summary on the line after the opening quotes: the project (PEP 257, like
#      scikit-learn) starts it on the quotes' line; numpydoc 1.6 flags that.
# EX01 on methods and properties: their examples live in the class docstring
#      (checked for every public class and function).
UNCHECKED_CODES = {"ES01", "SA01", "RT02", "GL01"}
CHECKED_CODES = sorted(set(numpydoc_validate.ERROR_MSGS) - UNCHECKED_CODES)

# Known failures, (name, code): the docstring is owned by work in progress. Shrink
# this list; test_allowed_failures_still_fail reports entries that pass now.
ALLOWED_FAILURES = {
    # summary starts "Names ..." / "Frames ...", not with a verb (SS05)
    ("skgesture.ActivitySegmenter.get_feature_names_out", "SS05"),
    ("skgesture.DynamicPoseWindow.get_feature_names_out", "SS05"),
    ("skgesture.PoseDescriptor.get_feature_names_out", "SS05"),
    # return description starts in lower case (RT04)
    ("skgesture.DynamicPoseWindow.transform", "RT04"),
    # no Parameters / Returns sections (PR01, RT01)
    ("skgesture.layouts.SkeletonLayout.index", "PR01"),
    ("skgesture.layouts.SkeletonLayout.index", "RT01"),
    ("skgesture.layouts.SkeletonLayout.indices", "PR01"),
    ("skgesture.layouts.SkeletonLayout.indices", "RT01"),
}


def _members(cls, qualname):
    """Public methods and properties that skgesture defines on ``cls``."""
    for name in sorted(vars(cls).keys() | {n for n, _ in inspect.getmembers(cls)}):
        if name.startswith("_"):
            continue
        try:
            raw = inspect.getattr_static(cls, name)
        except AttributeError:
            continue
        func = raw.fget if isinstance(raw, property) else getattr(raw, "__func__", raw)
        if not (inspect.isfunction(func) or isinstance(raw, property)):
            continue
        if not getattr(func, "__module__", "").startswith("skgesture"):
            continue  # inherited from scikit-learn, skorch, enum...
        yield f"{qualname}.{name}"


def _documented_objects(module_name):
    """``(dotted name, is_member)`` of the classes, functions and their members
    that ``module_name`` is the first public module to export."""
    owner = {}
    for mod_name in PUBLIC_MODULES:
        module = importlib.import_module(mod_name)
        for name in getattr(module, "__all__", ()):
            try:
                obj = getattr(module, name)
            except (AttributeError, ImportError):
                continue  # reported by test_api_reference_lists_every_public_name
            if inspect.isclass(obj) or inspect.isfunction(obj):
                owner.setdefault(id(obj), (mod_name, name, obj))
    for mod_name, name, obj in owner.values():
        if mod_name != module_name:
            continue
        qualname = f"{mod_name}.{name}"
        yield qualname, False, obj
        if inspect.isclass(obj):
            for member in _members(obj, qualname):
                yield member, True, None


def _failures(qualname, is_member, obj):
    result = numpydoc_validate.validate(qualname)
    for code, message in result["errors"]:
        if code not in CHECKED_CODES:
            continue
        if code == "EX01" and is_member:
            continue
        if code == "PR01" and isinstance(obj, enum.EnumMeta):
            continue  # the signature numpydoc sees is EnumMeta.__call__'s
        yield code, message


@pytest.mark.parametrize("module_name", PUBLIC_MODULES)
def test_docstrings_are_numpydoc_valid(module_name):
    failures = []
    for qualname, is_member, obj in _documented_objects(module_name):
        for code, message in _failures(qualname, is_member, obj):
            if (qualname, code) not in ALLOWED_FAILURES:
                failures.append(f"{qualname} {code}: {message}")
    assert not failures, "numpydoc validation failed:\n" + "\n".join(failures)


def test_allowed_failures_still_fail():
    objects = {}
    for module_name in PUBLIC_MODULES:
        for qualname, is_member, obj in _documented_objects(module_name):
            objects[qualname] = (is_member, obj)
    stale = []
    for qualname, code in sorted(ALLOWED_FAILURES):
        if qualname not in objects:
            stale.append(f"{qualname} (no longer public)")
            continue
        codes = {c for c, _ in _failures(qualname, *objects[qualname])}
        if code not in codes:
            stale.append(f"{qualname} {code}")
    assert not stale, f"remove from ALLOWED_FAILURES, these pass now: {stale}"


# --------------------------------------------------------------------------------
# Citations: every cited section exists

CITING = ["skgesture", "tests", "examples", "benchmarks", "docs"]
SKIP_DIRS = {"_build", "generated", "auto_examples", "gen_modules", "__pycache__"}
# The later rewrite of the non-shipping references, applied here in memory so
# that the old spellings are checked against the pages that replace them.
REWRITES = [
    (re.compile(r"(?:spec/)?METHOD_SPEC(?:\.md)?"), "docs/method.md"),
    (re.compile(r"(?<![\w/])DESIGN(?:\.md)?(?= §)"), "docs/design.md"),
]
# A "§" reference belongs to the page named just before it (within LOOKBACK
# characters), else to the citing file's own page: method.md for code.
PAGES = (
    "docs/method.md",
    "docs/design.md",
    "STYLE.md",
    "streaming.md",
    "benchmarks.md",
)
LOOKBACK = 60
_SECTION = re.compile(r"§\s*(\d+(?:\.\d+)*)(?:\s*[-–]\s*§?\s*(\d+(?:\.\d+)*))?")
_DECISION = re.compile(
    r"\b(?:decisions?|choice)\s+D(\d+)(?:\s*[-–]\s*D(\d+))?|§[\d.]+,\s*D(\d+)\b"
)


def _sections(page):
    text = (DOCS / page).read_text(encoding="utf-8")
    # "## §8.6 Title" headings, and "* **§11.3** ..." items of a numbered list
    numbered = set(re.findall(r"^#+ §(\d+(?:\.\d+)*)\s", text, flags=re.M))
    numbered |= set(re.findall(r"^\* \*\*§(\d+(?:\.\d+)*)\*\*", text, flags=re.M))
    titles = set(re.findall(r"^#+ (.+?)\s*$", text, flags=re.M))
    return numbered, titles, text


def _citing_files():
    for top in CITING:
        for path in sorted((ROOT / top).rglob("*")):
            if path.suffix not in {".py", ".md", ".rst", ".txt"}:
                continue
            if SKIP_DIRS.intersection(path.relative_to(ROOT).parts):
                continue
            if path == Path(__file__).resolve():
                continue  # the patterns above
            text = path.read_text(encoding="utf-8")
            for pattern, replacement in REWRITES:
                text = pattern.sub(replacement, text)
            yield path, text


def _range(start, end):
    """Both ends of "§3.9-3.11" or "§8.6.3-4" (= 8.6.3 to 8.6.4)."""
    if end is None:
        return [start]
    a, b = start.split("."), end.split(".")
    if len(b) < len(a):
        b = a[: len(a) - len(b)] + b
    return [start, ".".join(b)]


def test_cited_sections_exist():
    method_sections, _, method_text = _sections("method.md")
    design_sections, design_titles, _ = _sections("design.md")
    known = {"docs/method.md": method_sections, "docs/design.md": design_sections}
    decisions = set(re.findall(r"^\| D(\d+) \|", method_text, flags=re.M))
    assert decisions == {str(i) for i in range(1, 21)}, "method.md §10 lost a row"
    broken = []
    for path, text in _citing_files():
        own = "docs/design.md" if path == DOCS / "design.md" else "docs/method.md"
        for match in _SECTION.finditer(text):
            before = text[max(0, match.start() - LOOKBACK) : match.start()]
            found = [(before.rfind(p), p) for p in PAGES if p in before]
            page = max(found)[1] if found else own
            if page not in known:
                continue
            for number in _range(*match.groups()):
                if number not in known[page]:
                    line = text.count("\n", 0, match.start()) + 1
                    where = f"{path.relative_to(ROOT)}:{line}"
                    broken.append(f"{where}: {page} has no section §{number}")
        for match in _DECISION.finditer(text):
            for number in filter(None, match.groups()):
                if number not in decisions:
                    line = text.count("\n", 0, match.start()) + 1
                    where = f"{path.relative_to(ROOT)}:{line}"
                    broken.append(f"{where}: no decision D{number} in method.md §10")
        quoted = (
            r"docs/design\.md,?\s*(?:\"([^\"]{1,60})\"|'([^']{1,60})'|“([^”]{1,60})”)"
        )
        for groups in re.findall(quoted, text):
            title = " ".join("".join(groups).split())
            if not any(t == title or t.endswith(" " + title) for t in design_titles):
                broken.append(f"{path.relative_to(ROOT)}: design.md has no {title!r}")
    assert not broken, "unresolvable citations:\n" + "\n".join(broken)


def test_no_citation_of_non_shipping_files():
    offenders = []
    for path in sorted((ROOT / "skgesture").rglob("*.py")):
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if re.search(r"METHOD_SPEC|\bDESIGN(?:\.md)?\b", line):
                offenders.append(f"{path.relative_to(ROOT)}:{number}")
    assert not offenders, (
        "cite docs/method.md or docs/design.md instead of the non-shipping "
        f"METHOD_SPEC / DESIGN.md: {offenders}"
    )
