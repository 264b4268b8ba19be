"""cocotb testbenches; each module drives one generated Verilog top."""
