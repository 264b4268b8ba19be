"""The layers of ``docs/architecture.md`` point one way: no module imports from a layer above
its own, the shared specification and the host library need no HDL, and the gateware never
imports the simulation or the build flow."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: Layers from the bottom; a module may import from its own layer and the ones before it.
LAYERS = [
    ("spec",),
    ("gateware.wire", "gateware.registers", "gateware.cdc", "gateware.compose", "gateware"),
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


def imports(path, package):
    """Absolute names of everything the file imports (relative imports resolved)."""
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
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
