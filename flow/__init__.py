"""The build flow and the command line: Verilog, the ISE tree, resources, benchmarks, the system run.

``python -m flow <verilog|resources|bench|sim|waves>`` (the Makefile's targets). Not part of the
installed packages: it runs from the repository, beside :mod:`sim`, whose models it drives.
"""
