"""Simulation: behavioural models of the chips around the FPGA, harnesses, cocotb testbenches,
benchmarks, formal checks and the whole-system rigs.

A module's file name is unique in the repository (``spec``, ``gateware``, ``host``, ``sim``,
``flow``, ``tests``), and in five folders its last word says what it is
(``tests/test_module_names.py`` holds them to it):

``models/<subject>_model``
    A model of a chip or a block, the oracle its tests check against (``dlpc410_model``,
    ``mcb_model``, ``net_model``). ``<subject>_stim``: stimulus and checks shared by a block's
    tests; the others (``frames``, ``endpoint_traffic``, ``dlpc410_driver``, ``mcb_client``,
    ``trace``, ...) are test inputs and readers named for what they hold.
``tb/<subject>_tb``
    A cocotb testbench, the module ``cocotb_run.run(module="sim.tb.<subject>_tb")`` runs; its
    docstring names the pytest test that runs it, whose docstring names it back. The others are
    what testbenches and tests build on: tops made for a test (``store_chain``, ``ethernet_pins``,
    ``plane_source``), cocotb helpers (``gmii_host``), Amaranth-simulator runs (``*_sim``).
``bench/<subject>_figures``
    A benchmark: ``run()`` gives its figures (``make bench`` runs those :data:`sim.bench.MODULES`
    lists; most print theirs with ``python -m sim.bench.<subject>_figures``). ``tables`` and
    ``rig_rate`` serve them.
``rigs/<subject>_rig``, ``rigs/<subject>_run``
    A rig: a generated top with its surroundings in Verilog, no Python per cycle, driven by
    ``tb/<subject>_rig_tb``. A run: a whole-system simulation (``system_run``: ``make sim``'s entry
    and the small core's run of ``tb/system_tb``; ``xga_run``: the full-XGA run on
    ``fast_system_rig``; ``virtual_run``: the virtual projector). ``rigs/scene``: the default scene.

``formal/<subject>_properties``
    The formal properties of a block, or of every stream (``stream_properties``), that
    ``formal/suite`` lists and ``make formal`` checks; ``harness``, ``suite``, ``tools`` and
    ``geometry`` run them.

``harness/`` runs the Amaranth simulator and cocotb,
``hdl/`` the Verilog models and ``plans/`` the plan ``make sim`` ships
(:data:`sim.rigs.xga_run.SHIPPED_PLANS`).
"""
