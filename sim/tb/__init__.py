"""cocotb testbenches (``*_tb``: each drives one generated Verilog top, and names the test that
runs it), and the tops, fixtures and helpers they and the tests build on."""
