"""Rigs and runs: whole simulations of generated Verilog with no Python per cycle.

A rig (``*_rig``) is a generated top with its surroundings in Verilog, built once with Verilator
and driven by a cocotb testbench of ``sim/tb`` (``<rig>_tb``); a run (``*_run``) is what
``make sim`` plays on them; :mod:`.scene` is the scene the runs show.
"""
