"""The package's architecture as tests: stages import only the stages below them.

Every import counts, also those inside functions (they hide circles). The layers,
bottom to top (one number each; a stage may import the stages with a smaller one):

====  =========================================================================
0     ``core``: primitives, tolerances, errors, the mesh result (no torch)
1     ``model``: sketches, curve networks, patch sets
2     ``io``: readers and writers
3     ``snap``, ``cycles``, ``evaluate``: the stages on the data model
4     ``route`` (which calls the backends), ``cad``, ``datasets``
5     ``view``: pictures
6     ``review``: patch review in front of a user
7     ``pipeline``
8     ``batch``
9     ``cli``; ``__init__`` (lazy re-exports of the public names)
====  =========================================================================

The backends ``surfacing`` and ``neural`` import ``curvenet.core`` and themselves only,
never each other.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LAYERS = {"core": 0, "model": 1, "io": 2, "snap": 3, "cycles": 3, "evaluate": 3, "route": 4,
          "cad": 4, "datasets": 4, "view": 5, "review": 6, "pipeline": 7, "batch": 8,
          "cli": 9, "": 9}
BACKENDS = ("surfacing", "neural")
#: Largest module, in lines.
MAX_LINES = 600


def _modules() -> dict:
    """Dotted name -> (path, is a package ``__init__``) of every library module."""
    out = {}
    for folder, prefix in (("curvenet", "curvenet"), ("surfacing", "curvenet.surfacing"),
                           ("neural", "curvenet.neural")):
        for path in (ROOT / folder).rglob("*.py"):
            parts = list(path.relative_to(ROOT / folder).with_suffix("").parts)
            is_pkg = parts[-1] == "__init__"
            out[".".join([prefix] + parts[:len(parts) - is_pkg])] = (path, is_pkg)
    return out


MODULES = _modules()


def _imports(name: str):
    """``(target module, imported name or None, line)`` of every curvenet import."""
    path, is_pkg = MODULES[name]
    package = name if is_pkg else name.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module or ""
            if module.split(".")[0] == "curvenet":
                for alias in node.names:
                    full = f"{module}.{alias.name}"
                    yield (full if full in MODULES else module), alias.name, node.lineno
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "curvenet":
                    yield alias.name, None, node.lineno


def _stage(module: str) -> str:
    """``core``, ``snap``, ``surfacing`` ... of ``curvenet.X...``; ``""`` for ``curvenet``."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


EDGES = {m: sorted({t for t, _, _ in _imports(m)} - {m}) for m in MODULES}


def test_every_import_resolves_to_a_library_module():
    unknown = [(m, t) for m, targets in EDGES.items() for t in targets if t not in MODULES]
    assert not unknown


def test_stages_import_only_the_stages_below_them():
    wrong = []
    for m, targets in EDGES.items():
        a = _stage(m)
        for t in targets:
            b = _stage(t)
            if a in BACKENDS:
                ok = b in (a, "core")
            else:
                ok = a == b or b in BACKENDS and LAYERS[a] >= LAYERS["route"] \
                    or b not in BACKENDS and LAYERS[b] < LAYERS[a]
            if not ok:
                wrong.append(f"{m} -> {t}")
    assert not wrong, "\n".join(wrong)


def test_the_import_graph_has_no_circle():
    # Tarjan's strongly connected components, counting imports inside functions
    index, low, stack, on, circles = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in EDGES[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while not comp or comp[-1] != v:
                comp.append(stack.pop())
                on.discard(comp[-1])
            if len(comp) > 1:
                circles.append(sorted(comp))

    for v in MODULES:
        if v not in index:
            visit(v)
    assert not circles, circles


def test_no_module_imports_its_own_package_or_another_module_s_private_names():
    wrong = []
    for m, (_path, is_pkg) in MODULES.items():
        for t, name, line in _imports(m):
            if not is_pkg and MODULES.get(t, (None, False))[1] and m.startswith(t + "."):
                wrong.append(f"{m}:{line} imports its package {t}")
            if name and name.startswith("_") and not name.startswith("__") and t != m \
                    and not is_pkg:
                wrong.append(f"{m}:{line} imports {t}.{name}")
    assert not wrong, "\n".join(wrong)


def test_the_top_level_is_small_and_no_module_is_long():
    top = [p.name for p in (ROOT / "curvenet").glob("*.py")]
    subpackages = [p.name for p in (ROOT / "curvenet").iterdir() if (p / "__init__.py").is_file()]
    assert len(top) <= 12, top
    assert len(subpackages) >= 5, subpackages
    assert set(subpackages) <= set(LAYERS), set(subpackages) - set(LAYERS)
    long = {m: n for m, (p, _) in MODULES.items()
            if (n := len(p.read_text().splitlines())) > MAX_LINES}
    assert not long, long


@pytest.mark.parametrize("module", ["curvenet", "curvenet.core", "curvenet.snap",
                                    "curvenet.cycles", "curvenet.route", "curvenet.cli"])
def test_graph_stages_do_not_import_torch(module):
    code = f"import sys, {module}; assert 'torch' not in sys.modules, '{module}'"
    subprocess.run([sys.executable, "-c", code], check=True)


def test_core_imports_no_third_party_heavier_than_trimesh():
    # the bottom floor: numpy, scipy, trimesh, igl; never torch, matplotlib or networkx
    for path in (ROOT / "curvenet" / "core").glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module] if isinstance(node, ast.ImportFrom) and not node.level
                     else [])
            for name in names:
                assert name.split(".")[0] not in ("torch", "matplotlib", "networkx"), \
                    f"{path.name} imports {name}"
