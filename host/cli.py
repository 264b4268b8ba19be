"""Command line: ``python -m host send IMAGE...``, ``configure``, ``arm``/``disarm``, ``trigger`` and
``status``; ``master ADDRESS`` for a tiled display's sync master; ``dual A B IMAGE...`` for two
DMDs in weighted light (:mod:`host.weighted`).

``send`` sizes records to the path MTU (``--mtu`` to say it), continues after the newest frame id
the projector has (``--frame`` to choose), sends each frame at the smallest bit depth that shows it
within ``--tolerance`` LSB (``--depth`` to fix it), with ``--delta`` sends a scene's images as delta
frames of the last whole frame where few rows changed, and checks in a status reply that the
projector took every record (``--no-check`` not to). ``master`` sets the sync master's trigger
(times in seconds), fires a software trigger and prints its status."""

import argparse
import dataclasses
import json
import sys

import numpy as np

from spec import group_orders, plan_search, schedule
from spec.facts import DMDS, SETTLE_READINGS
from spec.registers import ResetMode, TriggerMode

from . import weighted
from .client import DEFAULT_PORT, DELTA_ROWS, Client, ClientError, MasterClient, period_fault

__all__ = ["main", "describe"]


def _load(path):
    """A grey image from ``.npy`` (8-bit, or real targets in 0..255) or any format Pillow reads."""
    try:
        if path.endswith(".npy"):
            image = np.load(path)
        else:
            try:
                from PIL import Image
            except ImportError:
                raise ClientError(f"{path}: reading image files needs Pillow "
                                  "(pip install 'dmd-projector[images]'); .npy needs nothing") from None
            image = np.asarray(Image.open(path).convert("L"))
    except (OSError, ValueError) as error:
        raise ClientError(f"cannot read {path}: {error}") from error
    if image.ndim != 2 or not (image.dtype == np.uint8 or np.issubdtype(image.dtype, np.floating)):
        raise ClientError(f"{path}: need a 2-D 8-bit or real image, got {image.dtype} {image.shape}")
    return image


def _t_rst(args):
    """``--t-rst``: cycles, ``measured`` (the projector's longest RST_ACTIVE so far, from its
    status), or ``None`` (the facts table's)."""
    if args.t_rst is None:
        return None
    if args.t_rst != "measured":
        return int(args.t_rst)
    with Client(args.address, args.port, timeout=args.timeout) as client:
        measured = client.status()["rst_active_cycles_max"]
    if not measured:
        raise ClientError("the projector has made no clocking pulse yet, so it has measured no RST_ACTIVE: "
                          "show a frame first")
    return measured


def _plan(args):
    dmd = DMDS[args.dmd]
    common = dict(depth=args.depth, exposure_s=args.exposure, words_per_cycle=args.read_rate,
                  t_rst_cycles=_t_rst(args), reading=args.settle_reading, anchor=args.anchor,
                  strict_rst=args.rst_active == "strict")
    if args.chained and not args.group_orders:
        raise ClientError("--chained plans with --group-orders")
    if args.group_orders:
        plan = _group_orders(dmd, args, common)
    elif args.best:
        found = plan_search.find(dmd, args.dclk, **common)
        print(f"plan finder: every reset mode, plane order and hide threshold under the {args.settle_reading} "
              f"settle reading and the {args.rst_active} RST_ACTIVE reading\n{found.table()}\n"
              f"fastest: {found.binds}")
        plan = found.plan
    else:
        plan = schedule.plan(dmd, args.dclk, reset_mode=ResetMode[args.reset_mode],
                             **plan_search.order_kwargs(plan_search.ORDER_NAMES[args.order], args.depth), **common)
    trigger = TriggerMode[args.trigger.upper()]
    given = round(args.period * schedule.FABRIC_HZ)
    if trigger == TriggerMode.PERIODIC:
        period = given or plan.trigger_cycles
    elif trigger == TriggerMode.SYNC:
        period = given          # the sync master's period: the clock loop's (0: the loop off)
    else:
        period = plan.params.period
    params = dataclasses.replace(plan.params, trigger=trigger, period=period)
    plan = dataclasses.replace(plan, params=params)
    fault = period_fault(plan)
    if fault:
        raise ClientError(fault)
    return dmd, plan


def _group_orders(dmd, args, common):
    """``--group-orders SECONDS``: each group of the reset mode in a plane order of its own, from
    an offset of its own, as the solver finds them (:func:`spec.group_orders.find`: 8-bit frames,
    TI's readings, the shortest LSB; ``common``: the plan's arguments, as :func:`_plan` read
    them)."""
    given = {"--depth": args.depth != 8, "--exposure": args.exposure, "--anchor": args.anchor,
             "--settle-reading": args.settle_reading != "ti", "--rst-active": args.rst_active != "strict"}
    if any(given.values()):
        raise ClientError(f"--group-orders plans 8-bit frames at the shortest LSB under TI's readings, from "
                          f"the order's start: not with {', '.join(k for k, v in given.items() if v)}")
    try:
        found = group_orders.find(dmd, args.dclk, ResetMode[args.reset_mode], seconds=args.group_orders,
                                  chained=args.chained, words_per_cycle=common["words_per_cycle"],
                                  t_rst_cycles=common["t_rst_cycles"])
    except ImportError:
        raise ClientError("--group-orders needs the constraint solver: pip install 'dmd-projector[solver]'") from None
    if found is None:
        raise ClientError(f"the solver found no plan the sequencer plays on time in {args.group_orders:g} s")
    plan, _ = found
    print("groups in plane orders of their own (spec.group_orders), offset and order of each:")
    for g, (offset, table) in enumerate(zip(plan.params.group_offsets, plan.params.group_tables, strict=True)):
        print(f"  group {g:2}  offset {offset:>7}  order {' '.join(map(str, table))}")
    return plan


def describe(plan):
    """What a register set reaches, from the schedule model: one line."""
    p = plan.params
    # durations are in ``dmd`` cycles (200 MHz) at either DCLK
    return (f"{plan.rate_hz:.1f} frames/s ({plan.frame_cycles} cycles of {schedule.FABRIC_HZ / 1e6:g} MHz "
            f"per frame), least significant plane {p.lsb} cycles ({p.lsb / schedule.FABRIC_HZ * 1e6:.2f} us), "
            f"set by {plan.binds}")


def _print_status(status):
    for name, value in status.items():
        print(f"{name:24} {value}")


def _master(args):
    """``master``: configure the sync master, then fire a software trigger, then print its
    status, as asked (its status alone when nothing is)."""
    settings = {"mode": TriggerMode[args.mode.upper()] if args.mode else None, "armed": args.armed,
                "period_s": args.period, "min_period_s": args.min_period, "width_s": args.width}
    settings = {name: value for name, value in settings.items() if value is not None}
    with MasterClient(args.address, args.port, timeout=args.timeout) as master:
        if settings:
            now = master.configure(**settings)
            print(f"sync master: mode {TriggerMode(now['mode']).name.lower()}, "
                  f"{'armed' if now['armed'] else 'disarmed'}, period {now['period']}, "
                  f"min_period {now['min_period']}, width {now['width']} cycles")
        if args.trigger:
            master.trigger()
        if args.status or not (settings or args.trigger):
            _print_status(master.status())


def _parser():
    """The command line's parser: the projector's address, then one subcommand."""
    parser = argparse.ArgumentParser(prog="python -m host", description=__doc__)
    parser.add_argument("--address", default="192.168.1.10", help="projector IPv4 address")
    parser.add_argument("--port", type=int, default=DEFAULT_PORT)
    parser.add_argument("--timeout", type=float, default=1.0, help="seconds to wait for a reply")
    sub = parser.add_subparsers(dest="command", required=True)
    _send_parser(sub)
    _sequence_parser(sub)
    _configure_parser(sub)
    for name, text in (("arm", "let triggers reach the sequencer"), ("disarm", "ignore every trigger"),
                       ("trigger", "a software trigger (the sequencer's trigger mode must be software)")):
        sub.add_parser(name, help=text)
    sub.add_parser("status", help="print the projector's counters")
    _master_parser(sub)
    _dual_parser(sub)
    return parser


def _dual_parser(sub):
    """``dual``: two DMDs in weighted light, each board at an address of its own."""
    dual = sub.add_parser("dual", help="n-bit frames (up to 16) on two boards in weighted light: board A the high "
                                       "bits at full light, board B the low bits at 2**-k of it")
    dual.add_argument("address_a", help="board A's IPv4 address (the high bits), ADDRESS or ADDRESS:PORT")
    dual.add_argument("address_b", help="board B's IPv4 address (the low bits), ADDRESS or ADDRESS:PORT")
    dual.add_argument("images", nargs="*", help=".npy files of n-bit images (uint16); two or more: a stored sequence")
    dual.add_argument("--bits", type=int, default=12, help="bits of a frame, 2..16 (default 12)")
    dual.add_argument("--low-bits", type=int, default=None, help="bits board B shows (default: --bits // 2)")
    dual.add_argument("--dmd", default="dlp7000", choices=sorted(DMDS))
    dual.add_argument("--dclk", type=float, default=400e6, help="DCLK in Hz the boards were built for")
    dual.add_argument("--ratio-error", type=float, default=0.0,
                      help="board B's light relative to 2**-k of A's, less 1, as a flat field measured it "
                           "(host.weighted.measure): the dim board's planes are lengthened")
    dual.add_argument("--sync-period", type=float, default=0.0,
                      help="the sync master's period in seconds, for the boards' clock loops (default: off)")
    dual.add_argument("--best", action="store_true",
                      help="both boards under the plan finder's fastest plan (spec.plan_search) at their depth")
    dual.add_argument("--dry-run", action="store_true", help="plan and say the rate; send nothing")


def _dual(args):
    """``dual``: plan both boards, trim, and send each its registers and its images."""
    dmd = DMDS[args.dmd]
    plan = weighted.plan(dmd, args.dclk, args.bits, args.low_bits, best=args.best)
    trim = weighted.trim(plan, args.ratio_error, dmd) if args.ratio_error else None
    period = weighted.trimmed_frame_cycles(plan, trim, dmd) if trim else plan.plan.frame_cycles
    print(f"{dmd.name}, {args.bits}-bit as {plan.high_bits} + {plan.low_bits} bits, both boards at "
          f"{plan.depth} bits: {schedule.FABRIC_HZ / period:.1f} Hz; light board B at 2**-{plan.low_bits} "
          f"of A; {describe(plan.plan)}")
    if trim:
        print(f"trim: lsb A {trim.lsb_a}, B {trim.lsb_b} cycles (plan {plan.lsb}), ratio error left "
              f"{trim.residual:+.2e}")
    if args.dry_run:
        return
    images = [np.load(path) for path in args.images]
    sync = round(args.sync_period * schedule.FABRIC_HZ)
    for board, address in (("a", args.address_a), ("b", args.address_b)):
        parts = [plan.images(image)[board] for image in images]
        host, _, port = address.partition(":")
        with Client(host, int(port) if port else args.port, timeout=args.timeout) as client:
            board_plan = dataclasses.replace(plan.plan, params=plan.board_params(board, trim, sync))
            client.configure(board_plan, dmd)
            client.control(bit_depth=plan.depth)
            if len(parts) > 1:
                client.play_sequence(parts, [{"slot": s} for s in range(len(parts))], depth=plan.depth)
            elif parts:
                client.send_image(parts[0], depth=plan.depth)
        print(f"board {board.upper()} at {address}: registers and {len(parts)} frame(s) sent")


def _send_parser(sub):
    """``send``: images as consecutive frames."""
    send = sub.add_parser("send", help="send images as consecutive frames")
    send.add_argument("--mtu", type=int, default=None,
                      help="IP MTU of the path to the projector (default: what the system knows)")
    send.add_argument("images", nargs="+", help=".npy or image files, grey")
    send.add_argument("--frame", type=int, default=None,
                      help="frame id of the first image (default: after the projector's newest)")
    send.add_argument("--depth", type=int, default=None, help="bit depth, 1..8 (default: the smallest "
                      "that shows each frame within --tolerance)")
    send.add_argument("--tolerance", type=float, default=0.5, help="largest rounding error, 8-bit LSB")
    send.add_argument("--rate", type=float, default=100e6, help="pacing in bytes per second")
    send.add_argument("--delta", type=float, default=0.0, metavar="FRACTION",
                      help="send an image as a delta frame (only its changed rows) of the last whole frame "
                           f"sent when at most this fraction of its rows changed (e.g. {DELTA_ROWS}); "
                           "default 0: whole frames")
    send.add_argument("--no-check", action="store_true", help="do not check the status after each frame")


def _sequence_parser(sub):
    """``sequence``: images stored as a sequence, played by an entry table."""
    play = sub.add_parser("sequence", help="store images as a sequence and play it by an entry table")
    play.add_argument("images", nargs="+", help=".npy or image files, grey: frame k goes to slot k")
    play.add_argument("--entries", required=True,
                      help="JSON file: a list of entries, each {\"slot\": k} with optional \"lsb\", \"dark\" "
                           "(cycles), \"follow\", \"camera\", \"depth\" (planes shown, the most significant "
                           "below the \"skip\" left out; see docs/protocol.md)")
    play.add_argument("--once", action="store_true", help="play the entries once (default: in a loop)")
    play.add_argument("--depth", type=int, default=None, help="bit depth, 1..8 (default: as send chooses)")
    play.add_argument("--rate", type=float, default=100e6, help="pacing in bytes per second")
    play.add_argument("--mtu", type=int, default=None, help="IP MTU of the path to the projector")


def _configure_parser(sub):
    """``configure``: what the plan is made of, and what it may search."""
    configure = sub.add_parser("configure", help="plan a schedule, say the rate it reaches, send it")
    configure.add_argument("--dmd", default="dlp7000", choices=sorted(DMDS))
    configure.add_argument("--dclk", type=float, default=400e6,
                           help="DCLK in Hz the projector was built for (default 400e6; 200e6 for the older PROM)")
    configure.add_argument("--depth", type=int, default=8, help="bit-planes per frame, 1..8")
    configure.add_argument("--reset-mode", default="GLOBAL", choices=[m.name for m in ResetMode])
    configure.add_argument("--best", action="store_true",
                           help="search every reset mode, plane order and hide threshold for the fastest legal "
                                "plan (spec.plan_search; about two minutes on the DLP7000) instead of "
                                "--reset-mode and --order")
    configure.add_argument("--group-orders", type=float, default=0.0, metavar="SECONDS",
                           help="search this long with a constraint solver for a plan of --reset-mode's groups each "
                                "in a plane order of its own, from an offset of its own (faster than one order "
                                "for every group; 8-bit frames; needs the 'solver' extra; docs/bounds.md); "
                                "triggered, two searches this long (each load's slack for other groups' pulses, "
                                "and none)")
    configure.add_argument("--chained", action="store_true",
                           help="with --group-orders: every frame follows the one before without a trigger, each "
                                "group starting its next frame as it ends its own (a stored sequence played back "
                                "to back; faster still: no group waits for the last to be loaded again)")
    configure.add_argument("--order", default="MSB_FIRST", choices=list(plan_search.ORDER_NAMES),
                           help="plane order; INTERLEAVED: each short plane behind a long one (7 1 6 2 5 3 4 0)")
    configure.add_argument("--anchor", type=int, default=0, choices=range(8),
                           help="the position in the plane order a frame starts at (modulo its depth), "
                                "where the trigger or a tiled display's sync pulse lands (default 0)")
    configure.add_argument("--exposure", type=float, default=0.0,
                           help="least significant plane at least this long, seconds (0: shortest)")
    configure.add_argument("--trigger", default="external", choices=[m.name.lower() for m in TriggerMode],
                           help="what starts a frame: the trigger pin, a period, a software trigger "
                                "(python -m host trigger) or the sync input")
    configure.add_argument("--period", type=float, default=0.0,
                           help="periodic trigger: seconds between frames (default: the fastest the plan allows); "
                                "sync: the sync master's period, which turns the board's clock loop on (default: "
                                "off)")
    configure.add_argument("--t-rst", default=None,
                           help="RST_ACTIVE time to plan with, in cycles from the pulse, or 'measured': the "
                                "longest the projector has seen (status rst_active_cycles_max; default: the "
                                "facts table's 4.54 us)")
    configure.add_argument("--read-rate", type=float, default=1.0,
                           help="the store's read bandwidth in 64-bit words per DCLK cycle (row pacing)")
    configure.add_argument("--settle-reading", default="ti", choices=sorted(SETTLE_READINGS),
                           help="what the mirror settle time forbids: 'ti' (default; TI: no load while the "
                                "mirrors settle) or 'paper' (the four-DMD paper's reading, which TI's documents "
                                "forbid: loads while they settle, pulses a settle time apart); docs/bounds.md")
    configure.add_argument("--rst-active", default="strict", choices=["strict", "loose"],
                           help="what RST_ACTIVE forbids: 'strict' (default; any pulse while it is high) or "
                                "'loose' (a pulse of the blocks whose own RST_ACTIVE window is open, as TI's "
                                "phased rates suggest; docs/dlpc410_model.md)")
    configure.add_argument("--dry-run", action="store_true", help="say the rate, send nothing")


def _master_parser(sub):
    """``master``: a tiled display's sync master, at an address of its own."""
    master = sub.add_parser("master", help="a tiled display's sync master: set its trigger, fire it, "
                                           "print its status (the default)")
    master.add_argument("address", help="the sync master's IPv4 address")
    # SUPPRESS: without --port here, the one given before the command (or its default) holds
    master.add_argument("--port", type=int, default=argparse.SUPPRESS,
                        help=f"the master's UDP port (default: --port before the command, {DEFAULT_PORT})")
    master.add_argument("--mode", choices=[m.name.lower() for m in TriggerMode if m != TriggerMode.SYNC],
                        help="what starts a frame: the trigger pin, a period, a software trigger (--trigger)")
    arming = master.add_mutually_exclusive_group()
    arming.add_argument("--arm", dest="armed", action="store_const", const=True, help="obey triggers")
    arming.add_argument("--disarm", dest="armed", action="store_const", const=False, help="ignore every trigger")
    master.add_argument("--period", type=float, metavar="S", help="periodic trigger: seconds between frames")
    master.add_argument("--min-period", type=float, metavar="S",
                        help="seconds from a pulse before the next trigger is obeyed (the boards' frame period)")
    master.add_argument("--width", type=float, metavar="S", help="seconds each sync and camera pulse lasts")
    master.add_argument("--trigger", action="store_true", help="fire a software trigger (after the settings)")
    master.add_argument("--status", action="store_true", help="print the master's counters and settings")


def _send(client, args):
    """``send``: each image as a frame, then what each took and how well it shows."""
    images = [_load(path) for path in args.images]
    sent = client.send_sequence(images, args.frame, depth=args.depth, tolerance=args.tolerance,
                                delta=args.delta)
    for path, frame in zip(args.images, sent, strict=True):
        kind = f", delta of frame {frame.base} carrying {frame.rows} rows" if frame.delta else ""
        if frame.refused:
            kind = f", whole: its delta was refused ({frame.refused})"
        print(f"frame {frame.frame}: {path}, {frame.depth}-bit, {frame.records} records, "
              f"rounding error {frame.error_lsb:.3g} LSB{kind}")
    print(f"sent {len(images)} frame(s) in {sum(f.records for f in sent)} records "
          f"of at most {client.limit} bytes (MTU {client.mtu})")


def _sequence(client, args):
    """``sequence``: store the images, then play the entries the JSON file lists."""
    with open(args.entries) as f:
        entries = json.load(f)
    sent = client.play_sequence([_load(path) for path in args.images], entries, loop=not args.once,
                                depth=args.depth)
    print(f"sequence of {len(sent)} frames stored; {len(entries)} entries played "
          f"{'once' if args.once else 'in a loop'} from the next trigger")


def _configure(client, args, dmd, plan):
    """``configure``: send the plan :func:`_plan` made, and the bit depth it was made for."""
    client.configure(plan, dmd)
    client.control(bit_depth=args.depth)
    print("sent; the sequencer takes it when no frame is playing")


def main(argv=None):
    """Run one command; 0 on success, 1 with the error on stderr."""
    args = _parser().parse_args(argv)

    try:
        if args.command == "master":
            _master(args)
            return 0
        if args.command == "dual":
            _dual(args)
            return 0
        if args.command == "configure":
            dmd, plan = _plan(args)
            print(f"{dmd.name}, {args.depth}-bit: {describe(plan)}")
            if args.dry_run:
                return 0
        with Client(args.address, args.port, timeout=args.timeout, rate=getattr(args, "rate", None),
                    mtu=getattr(args, "mtu", None), check=not getattr(args, "no_check", False)) as client:
            if args.command == "send":
                _send(client, args)
            elif args.command == "sequence":
                _sequence(client, args)
            elif args.command == "configure":
                _configure(client, args, dmd, plan)
            elif args.command in ("arm", "disarm"):
                client.control(armed=int(args.command == "arm"))
            elif args.command == "trigger":
                client.control(software_trigger=True)
            else:
                _print_status(client.status())
    except (ClientError, ValueError) as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    return 0
