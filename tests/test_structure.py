"""Guards on the package's structure: import cycles, module size, standalone modules.

Everything here is static: the source files under ``skgesture/`` are parsed with
:mod:`ast`, never imported (``skgesture`` itself is imported only to locate the
package directory, which is cheap and torch-free).
"""

# SPDX-License-Identifier: BSD-3-Clause

import ast
import sys
from collections import deque
from pathlib import Path

import pytest

import skgesture

PACKAGE = "skgesture"
PACKAGE_DIR = Path(skgesture.__file__).resolve().parent
ROOT_DIR = PACKAGE_DIR.parent

MAX_LINES = 1_000
SIZE_EXEMPTION = "Longer than 1,000 lines because"


# --------------------------------------------------------------------------
# Module discovery
# --------------------------------------------------------------------------


def _module_name(path, package_dir=PACKAGE_DIR):
    """Dotted module name of a ``.py`` file; a package is its ``__init__``."""
    rel = path.relative_to(package_dir.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _discover_modules(package_dir=PACKAGE_DIR):
    """Map every module name under ``package_dir`` to its file (sorted by name)."""
    modules = {}
    for path in sorted(package_dir.rglob("*.py")):
        if "__pycache__" in path.parts:
            continue
        modules[_module_name(path, package_dir)] = path
    return dict(sorted(modules.items()))


def _location(path):
    try:
        return str(path.relative_to(ROOT_DIR))
    except ValueError:  # pragma: no cover - package outside the repository
        return str(path)


# --------------------------------------------------------------------------
# Import extraction
# --------------------------------------------------------------------------


def _is_type_checking(test):
    """Whether an ``if`` test is ``TYPE_CHECKING`` or ``typing.TYPE_CHECKING``."""
    if isinstance(test, ast.Name):
        return test.id == "TYPE_CHECKING"
    if isinstance(test, ast.Attribute):
        return test.attr == "TYPE_CHECKING"
    return False


def _is_import_module_call(node):
    """Whether ``node`` calls ``importlib.import_module`` or ``import_module``."""
    func = node.func
    if isinstance(func, ast.Attribute):
        return func.attr == "import_module"
    if isinstance(func, ast.Name):
        return func.id == "import_module"
    return False


def _iter_import_nodes(tree):
    """Yield every import-like node (at any depth), skipping ``if TYPE_CHECKING:``."""
    stack = [tree]
    while stack:
        node = stack.pop()
        if isinstance(node, ast.If) and _is_type_checking(node.test):
            # The guarded body never runs; its ``else`` branch does.
            stack.extend(reversed(node.orelse))
            continue
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        elif isinstance(node, ast.Call) and _is_import_module_call(node):
            yield node
        stack.extend(reversed(list(ast.iter_child_nodes(node))))


def _resolve_relative(module, is_package, level, target):
    """Absolute name for ``from <level dots><target> import ...`` inside ``module``."""
    base = module.split(".")
    if not is_package:
        base = base[:-1]  # a plain module's package is its parent
    if level > 1:
        if level - 1 >= len(base):
            return None  # beyond the top-level package: an ImportError at runtime
        base = base[: -(level - 1)]
    if target:
        base = [*base, *target.split(".")]
    return ".".join(base)


def _imported_names(node, module, is_package, modules):
    """Module names (possibly outside the package) that one import node names."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    if isinstance(node, ast.ImportFrom):
        if node.level:
            base = _resolve_relative(module, is_package, node.level, node.module)
            if base is None:
                return []
        else:
            base = node.module
        names = []
        for alias in node.names:
            candidate = f"{base}.{alias.name}"
            # ``from pkg import sub`` imports the submodule when it exists, and
            # always imports ``pkg`` first (covered as ``sub``'s parent package,
            # or named directly when ``alias`` is a plain attribute).
            names.append(candidate if candidate in modules else base)
        return names
    # importlib.import_module("...") with a literal first argument
    if node.args and isinstance(node.args[0], ast.Constant):
        name = node.args[0].value
        if isinstance(name, str):
            if name.startswith("."):
                package = None
                if len(node.args) > 1 and isinstance(node.args[1], ast.Constant):
                    package = node.args[1].value
                if not isinstance(package, str):
                    return []
                level = len(name) - len(name.lstrip("."))
                return [
                    _resolve_relative(package, True, level, name.lstrip(".")) or package
                ]
            return [name]
    return []


def _ancestors(name):
    """``a.b.c`` -> ``["a", "a.b"]``."""
    parts = name.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts))]


def build_import_graph(package_dir=PACKAGE_DIR):
    """Import graph of the package: ``{module: {imported_module: [where, ...]}}``.

    An edge ``A -> B`` exists for every package module ``B`` named by an import
    anywhere in ``A`` (module level, functions, methods, classes, and
    ``importlib.import_module`` with a literal string), except under
    ``if TYPE_CHECKING:``. Importing ``B`` also imports each of its ancestor
    packages, so ``A`` gets an edge to each of those too, except the ancestors
    ``A`` shares (they are already being imported while ``A`` runs). ``where``
    is ``"path:line"``, with a note for the implied parent-package edges.
    """
    modules = _discover_modules(package_dir)
    graph = {name: {} for name in modules}
    for module, path in modules.items():
        is_package = path.name == "__init__.py"
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        own_ancestors = set(_ancestors(module))
        if is_package:
            own_ancestors.add(module)
        where = _location(path)
        for node in _iter_import_nodes(tree):
            for target in _imported_names(node, module, is_package, modules):
                if target is None:
                    continue
                if target not in modules:
                    # ``import skgesture.x.attr``-style names that are no file:
                    # fall back to the nearest existing module.
                    existing = [a for a in _ancestors(target) if a in modules]
                    if not target.startswith(PACKAGE + ".") or not existing:
                        continue
                    target = existing[-1]
                site = f"{where}:{node.lineno}"
                if target != module:
                    _add_edge(graph, module, target, site)
                for parent in _ancestors(target):
                    if parent in modules and parent not in own_ancestors:
                        if parent != module:
                            note = f"{site} (imports parent package of {target})"
                            _add_edge(graph, module, parent, note)
    return graph


def _add_edge(graph, source, target, site):
    """Record ``source -> target`` at ``site`` (once per site)."""
    sites = graph[source].setdefault(target, [])
    if site not in sites:
        sites.append(site)


# --------------------------------------------------------------------------
# Cycle detection
# --------------------------------------------------------------------------


def strongly_connected_components(graph):
    """Tarjan's algorithm, iterative. Returns the SCCs, each a sorted list."""
    index_of, lowlink, on_stack = {}, {}, set()
    stack, components, counter = [], [], 0
    for root in sorted(graph):
        if root in index_of:
            continue
        work = [(root, iter(sorted(graph.get(root, ()))))]
        index_of[root] = lowlink[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            advanced = False
            for child in children:
                if child not in index_of:
                    index_of[child] = lowlink[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.get(child, ())))))
                    advanced = True
                    break
                if child in on_stack:
                    lowlink[node] = min(lowlink[node], index_of[child])
            if advanced:
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                lowlink[parent] = min(lowlink[parent], lowlink[node])
            if lowlink[node] == index_of[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                components.append(sorted(component))
    return components


def find_cycles(graph):
    """The import cycles: SCCs with more than one module, or a self-import."""
    return sorted(
        (
            component
            for component in strongly_connected_components(graph)
            if len(component) > 1 or component[0] in graph.get(component[0], ())
        ),
        key=lambda c: (-len(c), c),
    )


def _shortest_cycle(graph, component):
    """A shortest cycle through ``component[0]`` inside ``component``."""
    members = set(component)
    start = component[0]
    previous = {start: None}
    queue = deque([start])
    while queue:
        node = queue.popleft()
        for child in sorted(graph[node]):
            if child not in members:
                continue
            if child == start:
                path = [node]
                while previous[path[-1]] is not None:
                    path.append(previous[path[-1]])
                return [*reversed(path), start]
            if child not in previous:
                previous[child] = node
                queue.append(child)
    return [start]  # pragma: no cover - a component always has a cycle


def format_cycles(graph, cycles):
    """A report a developer can act on: per cycle, a path and every edge in it."""
    lines = [f"{len(cycles)} import cycle(s) among skgesture modules:"]
    for number, component in enumerate(cycles, 1):
        members = set(component)
        lines.append("")
        lines.append(
            f"Cycle {number}: {len(component)} modules: {', '.join(component)}"
        )
        path = _shortest_cycle(graph, component)
        lines.append("  for example: " + " -> ".join(path))
        lines.append("  every import between these modules (break at least one):")
        for source in component:
            for target in sorted(graph[source]):
                if target in members:
                    lines.append(f"    {source} -> {target}")
                    lines.extend(f"        at {site}" for site in graph[source][target])
    return "\n".join(lines)


# --------------------------------------------------------------------------
# Tests
# --------------------------------------------------------------------------


def test_cycle_finder_on_synthetic_graphs():
    """The cycle finder itself works, so an empty result means something."""
    cyclic = {"a": {"b": []}, "b": {"c": []}, "c": {"a": []}, "d": {"a": []}}
    assert find_cycles(cyclic) == [["a", "b", "c"]]
    assert _shortest_cycle(cyclic, ["a", "b", "c"]) == ["a", "b", "c", "a"]
    assert "a -> b -> c -> a" in format_cycles(cyclic, find_cycles(cyclic))

    dag = {"a": {"b": [], "c": []}, "b": {"c": []}, "c": {}, "d": {"a": []}}
    assert find_cycles(dag) == []

    two = {"a": {"b": []}, "b": {"a": []}, "c": {"d": []}, "d": {"c": [], "e": []}}
    two["e"] = {}
    assert find_cycles(two) == [["a", "b"], ["c", "d"]]
    assert find_cycles({"a": {"a": []}}) == [["a"]]

    # Deep chains must not hit the recursion limit.
    chain = {f"m{i}": {f"m{i + 1}": []} for i in range(5000)}
    chain["m5000"] = {"m0": []}
    assert len(find_cycles(chain)) == 1


def test_import_resolution_rules():
    """Relative imports, ``from pkg import sub`` and parent packages resolve."""
    assert _resolve_relative("skgesture.a.b", False, 1, "c") == "skgesture.a.c"
    assert _resolve_relative("skgesture.a", True, 1, "c") == "skgesture.a.c"
    assert _resolve_relative("skgesture.a.b", False, 2, None) == "skgesture"
    assert _resolve_relative("skgesture", True, 2, "x") is None
    assert _ancestors("skgesture.a.b") == ["skgesture", "skgesture.a"]

    graph = build_import_graph()
    # datasets/__init__.py imports its submodules (``from skgesture.datasets._base``).
    assert "skgesture.datasets._base" in graph["skgesture.datasets"]
    # A submodule importing a sibling does not get an edge to its own package.
    assert "skgesture.datasets" not in graph.get("skgesture.datasets._chalearn", {})


def test_no_import_cycles():
    """No import cycles among skgesture modules, counting every import.

    Imports inside functions, methods and classes count as much as module-level
    ones (they only defer the cycle to call time), and so does
    ``importlib.import_module("skgesture...")`` with a literal name; imports
    under ``if TYPE_CHECKING:`` do not. Importing ``skgesture.a.b`` also imports
    the package ``skgesture.a``, so that edge counts too, unless the importer is
    itself inside ``skgesture.a``.
    """
    graph = build_import_graph()
    n_edges = sum(len(targets) for targets in graph.values())
    assert len(graph) > 20, f"only {len(graph)} modules found under {PACKAGE_DIR}"
    assert n_edges > 30, f"only {n_edges} import edges found: is the parser broken?"

    cycles = find_cycles(graph)
    assert not cycles, format_cycles(graph, cycles)


def _module_docstring(path):
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    return ast.get_docstring(tree) or ""


def test_module_size():
    """Every module under skgesture/ has at most 1,000 lines.

    A longer module is allowed only when its module docstring says why, in a
    sentence that starts with the phrase "Longer than 1,000 lines because"
    (line breaks inside the phrase are fine), e.g.::

        Longer than 1,000 lines because the state machine and its tables must
        stay in one place to be readable.

    Split anything else into smaller modules.
    """
    offenders = []
    for path in _discover_modules().values():
        n_lines = len(path.read_text(encoding="utf-8").splitlines())
        if n_lines <= MAX_LINES:
            continue
        docstring = " ".join(_module_docstring(path).split())
        if SIZE_EXEMPTION in docstring:
            continue
        offenders.append((n_lines, _location(path)))
    offenders.sort(reverse=True)
    assert not offenders, (
        f"{len(offenders)} module(s) longer than {MAX_LINES:,} lines, with no "
        f"{SIZE_EXEMPTION!r} sentence in the module docstring:\n"
        + "\n".join(f"  {where}: {n:,} lines" for n, where in offenders)
    )


def test_stream_protocol_module_is_standalone():
    """skgesture/_stream.py imports only the standard library and numpy."""
    path = PACKAGE_DIR / "_stream.py"
    if not path.exists():
        pytest.skip("skgesture/_stream.py does not exist yet (being created)")
    module = _module_name(path)
    modules = _discover_modules()
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    allowed = set(sys.stdlib_module_names) | {"numpy", "__future__"}
    bad = []
    for node in _iter_import_nodes(tree):
        site = f"{_location(path)}:{node.lineno}"
        if isinstance(node, ast.ImportFrom) and node.level:
            bad.append(f"{site}: relative import (a skgesture module)")
            continue
        for name in _imported_names(node, module, False, modules):
            if name is None:
                continue
            top = name.split(".")[0]
            if top == PACKAGE or top not in allowed:
                bad.append(f"{site}: imports {name}")
    assert not bad, (
        "skgesture/_stream.py must import nothing but the standard library and "
        "numpy:\n" + "\n".join(f"  {line}" for line in bad)
    )


# -- layers (docs/design.md, "Module map", import rule 4) ---------------------------

# From the bottom up. A module belongs to the longest prefix listed; the package
# root (the lazy public API table) imports nothing but _legacy and _version, so it
# sits at the bottom, and utils._testing (a test helper that builds synthetic
# streams) at the top.
LAYERS = (
    ("skgesture", "skgesture._version", "skgesture._legacy", "skgesture._stream",
     "skgesture._rate", "skgesture.layouts", "skgesture.utils"),
    ("skgesture._descriptor", "skgesture._nn", "skgesture._augment",
     "skgesture.metrics"),
    ("skgesture._features", "skgesture._concat", "skgesture._segmenter",
     "skgesture._windows", "skgesture._multiscale", "skgesture._taggers"),
    ("skgesture._pipelines", "skgesture._gesture_pipeline", "skgesture.streaming",
     "skgesture._persistence", "skgesture.datasets"),
    ("skgesture._cli", "skgesture._cli_commands", "skgesture._cli_support",
     "skgesture.parallel", "skgesture.plotting", "skgesture.__main__",
     "skgesture.utils._testing"),
)  # fmt: skip


def _layer(module):
    """Index of the layer of ``module`` (longest matching prefix), or None."""
    best = None
    for i, prefixes in enumerate(LAYERS):
        for prefix in prefixes:
            if module == prefix or module.startswith(prefix + "."):
                if prefix == "skgesture" and module != "skgesture":
                    continue  # the root itself only
                if best is None or len(prefix) > best[1]:
                    best = (i, len(prefix))
    return None if best is None else best[0]


def test_every_import_goes_down_the_layers():
    """A module imports from its own layer or below (docs/design.md, rule 4)."""
    graph = build_import_graph()
    unlayered = sorted(m for m in graph if _layer(m) is None)
    assert not unlayered, f"modules in no layer of LAYERS: {unlayered}"
    upward = [
        f"  {source} (layer {_layer(source)}) -> {target} (layer {_layer(target)})"
        f" at {sites[0]}"
        for source, targets in sorted(graph.items())
        for target, sites in sorted(targets.items())
        if _layer(target) > _layer(source)
    ]
    assert not upward, "imports that go up the layers:\n" + "\n".join(upward)
    # The rule can fail: the CLI imports the pipelines, two layers up from utils.
    assert (
        _layer("skgesture._cli")
        > _layer("skgesture._pipelines")
        > _layer("skgesture.utils._validation")
    )


def test_the_module_map_lists_every_module():
    """docs/design.md §10 names every module, one line each, under its folder."""
    design = PACKAGE_DIR.parent / "docs" / "design.md"
    if not design.exists():
        pytest.skip("docs/ is not shipped with this copy of the package")
    text = design.read_text(encoding="utf-8")
    block = text[text.index("## §10 Module map") :].split("```")[1]
    folder, listed = None, set()
    for line in block.splitlines():
        entry = line.split()[0] if line.strip() else ""
        indent = len(line) - len(line.lstrip())
        if entry.endswith("/") and indent == 2:
            folder = entry.rstrip("/")
        elif entry.endswith(".py"):
            listed.add(entry if indent == 2 else f"{folder}/{entry}")
    missing = sorted(
        str(path.relative_to(PACKAGE_DIR))
        for path in PACKAGE_DIR.rglob("*.py")
        if (path.name != "__init__.py" or path.parent == PACKAGE_DIR)
        and str(path.relative_to(PACKAGE_DIR)) not in listed
    )
    assert not missing, f"modules missing from docs/design.md §10: {missing}"
