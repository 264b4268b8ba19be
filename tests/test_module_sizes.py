"""The house's sizes: a module past 600 lines wants to be a package, a function past 120 lines
(an ``elaborate`` among them) wants parts of its own. Held in the layers a reader of the design
opens first: ``spec``, ``gateware`` and ``host``."""

import ast
from pathlib import Path

ROOT = Path(__file__).parent.parent
LAYERS = ("spec", "gateware", "host")
MODULE_LINES, FUNCTION_LINES = 600, 120


def _modules():
    return sorted(path for layer in LAYERS for path in (ROOT / layer).rglob("*.py"))


def functions_over(source, limit):
    """``[(name, lines)]`` of the functions in ``source`` longer than ``limit`` lines."""
    return [(node.name, node.end_lineno - node.lineno + 1) for node in ast.walk(ast.parse(source))
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
            and node.end_lineno - node.lineno + 1 > limit]


def test_every_module_and_function_fits():
    long_modules, long_functions = [], []
    for path in _modules():
        text, name = path.read_text(), str(path.relative_to(ROOT))
        if len(text.splitlines()) > MODULE_LINES:
            long_modules.append((name, len(text.splitlines())))
        long_functions += [(name, *function) for function in functions_over(text, FUNCTION_LINES)]
    assert long_modules == [], "make these packages"
    assert long_functions == [], "give these functions parts of their own"


def test_the_check_sees_a_long_function():
    body = "".join(f"    x{i} = {i}\n" for i in range(FUNCTION_LINES))
    assert functions_over(f"def elaborate(self, platform):\n{body}", FUNCTION_LINES) == \
        [("elaborate", FUNCTION_LINES + 1)]
    assert functions_over(f"def short():\n{body[:-len(body.splitlines(True)[-1])]}", FUNCTION_LINES) == []
