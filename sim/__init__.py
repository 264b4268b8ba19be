"""Simulation: behavioural models of the chips around the FPGA, harnesses, cocotb testbenches,
benchmarks, formal checks and the whole-system rigs.

A module's file name is unique in the repository (``spec``, ``gateware``, ``host``, ``sim``,
``flow``, ``tests``; ``formal/``'s modules are named for the gateware they check) and ends in the
word for what it is, one word per folder:

``models/<subject>_model``
    A model of a chip or a block, the oracle its tests check against (``dlpc410_model``,
    ``mcb_model``, ``net_model``). ``<subject>_stim``: stimulus and checks shared by a block's
    tests; the others (``frames``, ``endpoint_traffic``, ``dlpc410_driver``, ``mcb_client``,
    ``trace``, ...) are test inputs and readers named for what they hold.
``tb/<subject>_tb``
    A cocotb testbench, the module ``cocotb_run.run(module="sim.tb.<subject>_tb")`` runs; its
    docstring names the pytest test that runs it, and the test's names it. The other modules are
    what testbenches and tests build on: tops made for a test (``store_chain``, ``ethernet_pins``,
    ``plane_source``), cocotb helpers (``gmii_host``), Amaranth-simulator runs (``*_sim``).
``bench/<subject>_figures``
    A benchmark of ``make bench`` (listed in :data:`sim.bench.MODULES`; ``python -m
    sim.bench.<subject>_figures`` prints its figures); ``tables`` and ``rig_rate`` serve them.
``rigs/<subject>_rig``, ``rigs/<subject>_run``
    A rig: a generated top with its surroundings in Verilog, no Python per cycle, driven by
    ``tb/<subject>_rig_tb``. A run: what ``make sim`` plays on them (``system_run``, ``xga_run``,
    ``virtual_run``). ``rigs/scene``: the default scene.

``harness/`` runs the Amaranth simulator and cocotb, ``formal/`` holds the formal properties,
``hdl/`` the Verilog models and ``plans/`` the plan ``make sim`` ships
(:data:`sim.rigs.xga_run.SHIPPED_PLANS`).
"""
