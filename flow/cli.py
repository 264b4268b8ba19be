"""Command line: ``python -m flow <verilog|resources|timing|formal|bench|figures|sim|waves>``."""

import argparse
import sys

__all__ = ["main"]


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m flow", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("verilog", help="write the Spartan-6 ISE tree and every block's Verilog to build/spartan6")
    resources = sub.add_parser("resources", help="Yosys synth_xilinx -family xc6s: LUT/FF/BRAM/DSP per block and "
                                                 "per board build (total: the DLP7000's, total_dlp9500: the "
                                                 "DLP9500's)")
    resources.add_argument("--block", action="append", default=None,
                           help="only this block of flow.blocks or board build of flow.resources.TOPS (repeatable)")
    resources.add_argument("--jobs", type=int, default=1, help="Yosys runs at a time (default 1)")
    timing = sub.add_parser("timing", help="logic depth between flip-flops per clock domain (Yosys, xc6s)")
    timing.add_argument("--block", default=None, help="one block of flow.blocks instead of the core")
    timing.add_argument("--over", action="append", default=[], metavar="DOMAIN",
                        help="list every register a path over the budget ends at, in this domain (repeatable)")
    timing.add_argument("--path", action="append", default=[], metavar="REGISTER",
                        help="the deepest path to the register named like this, cell by cell, with the named "
                             "signals each cell reads (repeatable)")
    timing.add_argument("--lut-delay", type=int, default=None, metavar="PS",
                        help="every LUT input's delay to the mapper (default 642 ps, Yosys' slowest input: the "
                             "conservative headline; 5000, far above a 16-bit carry chain's: the uniform mapping, "
                             "levels minimised as the budget counts them)")
    formal = sub.add_parser("formal", help="prove or check every formal property (SymbiYosys)")
    formal.add_argument("--quick", action="store_true", help="BMC to the test suite's depths, no proofs")
    formal.add_argument("--only", action="append", help="only this block (repeatable)")
    formal.add_argument("--jobs", type=int, default=1, help="checks run at a time")
    bench = sub.add_parser("bench", help="run the benchmarks and write build/bench.json")
    bench.add_argument("--only", action="append", help="run only this benchmark module (repeatable)")
    bench.add_argument("--no-resources", action="store_true", help="skip the synthesis figures")
    bench.add_argument("--merge", action="store_true",
                       help="replace only the figures measured now in build/bench.json, keep the others")
    sub.add_parser("figures", help="write docs/figures.md, the README's headline figures and the figures "
                                   "the README and docs/*.md quote, from build/bench.json")
    sim = sub.add_parser("sim", help="the system simulation on the default scene")
    sim.add_argument("--frames", type=int, default=None, help="number of frames to store and show")
    sim.add_argument("--dclk", type=float, default=400, choices=(200, 400), help="DCLK in MHz (default 400)")
    sim.add_argument("--dmd", default="dlp7000", choices=("dlp7000", "dlp9500"),
                     help="the DMD the core is built for (default dlp7000; dlp9500: four buses)")
    sim.add_argument("--faults", choices=("stalls", "rst", "all"), default=None,
                     help="memory stalls at random, RST_ACTIVE held longer than planned, or both "
                          "(sim.rigs.xga_run.FAULTS)")
    sim.add_argument("--group-orders", type=float, default=None, metavar="SECONDS",
                     help="play the constraint solver's plan, dual reset's groups each in a plane order of its own "
                          "(spec.group_orders), searched this long (kept in build/plans for later runs)")
    sim.add_argument("--window", action="store_true",
                     help="also dump every signal of the core from the first frame's last datagram (every frame "
                          "sent whole, that one held back) through the store to just after its first pulse, with "
                          "a GTKWave save file grouped by block")
    sim.add_argument("--virtual", default=None, metavar="SECONDS|demo",
                     help="the virtual projector: the small core on a TAP in a network namespace of its own, for "
                          "that many seconds, or 'demo' (the host CLI talks to it); needs root (sim.rigs.virtual_run)")
    sub.add_parser("waves", help="say where the latest VCD and its GTKWave save file are")
    args = parser.parse_args(argv)

    if args.command == "verilog":
        from flow.verilog import main as run
        return run()
    if args.command == "resources":
        from flow.resources import main as run
        return run(blocks=args.block, jobs=args.jobs)
    if args.command == "timing":
        from flow.timing import LUT_DELAY
        from flow.timing import main as run
        return run(block=args.block, over=args.over, path=args.path, lut_delay=args.lut_delay or LUT_DELAY)
    if args.command == "formal":
        from flow.formal import main as run
        return run(quick=args.quick, only=args.only, jobs=args.jobs)
    if args.command == "bench":
        from flow.bench import main as run
        return run(args.only, resources=not args.no_resources, merge=args.merge)
    if args.command == "figures":
        from flow.figures import main as run
        try:
            return run()
        except FileNotFoundError as error:
            print(error, file=sys.stderr)
            return 2
    if args.command == "sim" and args.virtual:
        from sim.rigs import virtual_run as virtual
        if args.virtual != "demo":
            return virtual.main(float(args.virtual))
        try:
            report = virtual.demo()
        except RuntimeError as error:
            print(error)
            return 2
        return 0 if report.get("max_error_lsb") == 0 else 1
    if args.command == "sim":
        from sim.rigs.system_run import main as run
        return run(frames=args.frames, dclk_hz=args.dclk * 1e6, faults=args.faults, window=args.window,
                   dmd=args.dmd, group_orders=args.group_orders)
    if args.command == "waves":
        from sim.harness.waves import main as run
        return run()
    return 2


if __name__ == "__main__":
    sys.exit(main())
