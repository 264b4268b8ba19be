"""The build side: Verilog, the Spartan-6 ISE tree, resource reports, benchmarks, the CLI."""
