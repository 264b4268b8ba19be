"""The PCS's reference model (:mod:`sim.models.pcs_model`) is an oracle apart from the gateware:
written from clause 36's tables on its own, it imports no gateware, no HDL and no other part of
the simulation, so that its agreement with the gateware in the PCS tests is worth having."""

import ast
from pathlib import Path

from sim.models import pcs_model as model

SOURCE = Path(model.__file__)


def test_model_imports_nothing_from_the_gateware():
    """The model is an oracle only while it is written apart: it imports no gateware at all."""
    tree = ast.parse(SOURCE.read_text())
    modules = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            modules |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            modules.add(node.module or "")
    assert not {name for name in modules if name.split(".")[0] in ("gateware", "amaranth")}
    assert not {name for name in modules if name.startswith("sim")}
