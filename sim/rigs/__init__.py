"""Rigs and runs: whole-system simulations.

A rig (``*_rig``) is a generated top with its surroundings in Verilog, built once with Verilator,
no Python per cycle, and driven by a cocotb testbench of ``sim/tb`` (``<rig>_tb``); a run
(``*_run``) is a whole-system simulation as ``make sim`` makes it; :mod:`.scene` is the scene the
runs show.
"""
