"""Harnesses: the Amaranth simulator (:mod:`.amaranth_sim`) and cocotb on generated Verilog
(:mod:`.cocotb_run`, :mod:`.layout`)."""
