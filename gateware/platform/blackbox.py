"""Verilog declarations of vendor-generated modules the platform tops instantiate, for tools that
read our Verilog without the vendor's sources (the resource report, the lint of a board's tree)."""

__all__ = ["blackbox_verilog"]

_KINDS = {"i": "input", "o": "output", "io": "inout"}


def blackbox_verilog(module, ports):
    """``(* blackbox *)`` module ``module`` with ``ports``: ``Instance`` keyword arguments
    (``i_``/``o_``/``io_`` + name) to values whose widths the ports take."""
    lines = []
    for key, value in ports.items():
        kind, name = key.split("_", 1)
        width = len(value)
        lines.append(f"  {_KINDS[kind]} {f'[{width - 1}:0] ' if width > 1 else ''}{name}")
    return f"(* blackbox *)\nmodule {module} (\n" + ",\n".join(lines) + "\n);\nendmodule\n"
