"""The layers of ``docs/architecture.md`` point one way: no module imports from a layer above
its own, the shared specification and the host library need no HDL, and the gateware never
imports the simulation or the build flow. Nor does any module import itself round a cycle of
module-level imports, within a layer or across."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: Layers from the bottom; a module may import from its own layer and the ones before it.
LAYERS = [
    ("spec",),
    ("gateware.wire", "gateware.registers", "gateware.cdc", "gateware.compose", "gateware"),
    ("gateware.pcs",),
    ("gateware.mac",),
    ("gateware.net",),
    ("gateware.protocol",),
    ("gateware.bitplane",),
    ("gateware.store",),
    ("gateware.dlpc410",),
    ("gateware.sync",),
    ("gateware.platform",),
    ("gateware.top",),
    ("host",),
    ("sim",),
    ("flow",),
]
#: Packages that must not reach the HDL toolchain at all (the host installs without it).
PURE = {"spec": {"spec"}, "host": {"spec", "host"}}


def layer_of(module):
    best = None
    for rank, prefixes in enumerate(LAYERS):
        for prefix in prefixes:
            if module == prefix or module.startswith(prefix + "."):
                if best is None or len(prefix) > best[1]:
                    best = (rank, len(prefix))
    return None if best is None else best[0]


def modules():
    for top in ("spec", "gateware", "host", "sim", "flow"):
        for path in sorted((ROOT / top).rglob("*.py")):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            package = parts[:-1] if parts[-1] != "__init__" else parts[:-1]
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            yield name, ".".join(package), path


def _names(node, package):
    """The absolute names an import statement gives: ``import a.b`` gives ``a.b``; ``from .m import
    x`` in package ``p`` gives ``p.m`` and ``p.m.x`` (``x`` may be a submodule)."""
    if isinstance(node, ast.Import):
        for alias in node.names:
            yield alias.name
    elif isinstance(node, ast.ImportFrom):
        if node.level:
            base = package.split(".")[:len(package.split(".")) - node.level + 1]
            stem = ".".join(base + ([node.module] if node.module else []))
        else:
            stem = node.module
        yield stem
        for alias in node.names:
            yield f"{stem}.{alias.name}"


def imports(path, package):
    """Absolute names of everything the file imports (relative imports resolved)."""
    for node in ast.walk(ast.parse(path.read_text())):
        yield from _names(node, package)


def module_level_imports(path, package):
    """What :func:`imports` gives, for the imports run when the module is imported: those at its
    top level and in its top-level ``if``/``try``/``with`` blocks and class bodies, not those in
    functions (run later, when the module is whole) nor under ``if TYPE_CHECKING:``."""
    def walk(body):
        for node in body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
                yield from walk(node.orelse)
                continue
            yield from _names(node, package)
            for field in ("body", "orelse", "finalbody", "handlers", "cases"):
                inner = getattr(node, field, None)
                if isinstance(inner, list):
                    yield from walk(inner)
    yield from walk(ast.parse(path.read_text()).body)


def import_graph(found):
    """``{module: modules it imports at module level}`` over ``found`` (``(name, package, path)``,
    as :func:`modules` gives), kept to those modules. Importing ``a.b.c`` runs ``a`` and ``a.b``
    too, so each imported name stands for its packages as well, except the importer's own (they
    are already being imported when it runs: no cycle goes through them)."""
    found = list(found)
    known = {name for name, _, _ in found}
    graph = {}
    for name, package, path in found:
        own = {".".join(name.split(".")[:i]) for i in range(1, name.count(".") + 2)}
        targets = set()
        for target in module_level_imports(path, package):
            parts = target.split(".")
            targets |= {".".join(parts[:i]) for i in range(1, len(parts) + 1)}
        graph[name] = sorted((targets & known) - own)
    return graph


def import_cycles(graph):
    """One cycle through each strongly connected part of ``graph`` of more than one module
    (Tarjan's), the shortest from the part's first module round to it: ``["a", "b", "a"]``."""
    index, low, stack, parts = {}, {}, [], []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            part = set(stack[stack.index(v):])
            del stack[stack.index(v):]
            if len(part) > 1:
                parts.append(part)

    def round_from(start, part):
        came, queue = {start: None}, [start]
        for v in queue:
            for w in graph[v]:
                if w == start:
                    way = [v]
                    while came[way[-1]] is not None:
                        way.append(came[way[-1]])
                    return [*reversed(way), start]
                if w in part and w not in came:
                    came[w] = v
                    queue.append(w)

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(round_from(min(part), part) for part in parts)


def test_no_module_imports_upward():
    upward = []
    for name, package, path in modules():
        own = layer_of(name)
        for target in set(imports(path, package)):
            rank = layer_of(target)
            # host sits beside the gateware, not above it: it may import only spec
            if name.startswith("host") and target.split(".")[0] == "gateware":
                upward.append(f"{name} imports {target} (the host needs no gateware)")
            elif rank is not None and own is not None and rank > own:
                upward.append(f"{name} (layer {own}) imports {target} (layer {rank})")
    assert not upward, "\n".join(sorted(upward))


def test_spec_and_host_need_no_hdl():
    bad = []
    for name, package, path in modules():
        top = name.split(".")[0]
        if top not in PURE:
            continue
        for target in set(imports(path, package)):
            root = target.split(".")[0]
            if root in ("amaranth", "amaranth_boards", "cocotb", "gateware", "sim", "flow"):
                bad.append(f"{name} imports {target}")
    assert not bad, "\n".join(sorted(bad))


def test_the_checker_sees_an_upward_import(tmp_path):
    """The import reader resolves relative imports: ``from ..top import x`` in
    ``gateware/net/a.py`` is ``gateware.top.x``, a layer above ``gateware.net``."""
    path = tmp_path / "a.py"
    path.write_text("from ..top import system\nfrom . import tap\n")
    found = set(imports(path, "gateware.net"))
    assert "gateware.top.system" in found and "gateware.net.tap" in found
    assert layer_of("gateware.top.system") > layer_of("gateware.net.a")


def test_no_module_level_import_cycle():
    """No module imports one that imports it back at module level, directly or round a longer
    cycle: the first to be imported would run on a partial module of the other. Imports inside
    functions do not count (they run when both modules are whole)."""
    cycles = import_cycles(import_graph(modules()))
    assert not cycles, "\n".join(" -> ".join(cycle) for cycle in cycles)


def test_the_checker_sees_an_import_cycle(tmp_path):
    """Two modules that import each other at module level (one through ``from . import``) are a
    cycle; the same pair with one import inside a function is none."""
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "a.py").write_text("from . import b\n")
    (pkg / "b.py").write_text("from .a import name\n")
    (pkg / "c.py").write_text("def f():\n    from . import d\n")
    (pkg / "d.py").write_text("if True:\n    from .c import f\n")
    found = [(f"pkg.{n}", "pkg", pkg / f"{n}.py") for n in "abcd"]
    graph = import_graph(found)
    assert graph == {"pkg.a": ["pkg.b"], "pkg.b": ["pkg.a"], "pkg.c": [], "pkg.d": ["pkg.c"]}
    assert import_cycles(graph) == [["pkg.a", "pkg.b", "pkg.a"]]
