"""Simulation: behavioural models of the chips around the FPGA, harnesses and cocotb testbenches."""
