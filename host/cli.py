"""Command line: ``python -m host send IMAGE...``, ``configure``, ``arm``/``disarm`` and ``status``."""

import argparse
import sys

import numpy as np

from spec import schedule
from spec.facts import DMDS
from spec.registers import PlaneOrder, ResetMode

from .client import DEFAULT_PORT, Client, ClientError

__all__ = ["main", "describe"]


def _load(path):
    """An 8-bit grey image from ``.npy`` or any format Pillow reads."""
    try:
        if path.endswith(".npy"):
            image = np.load(path)
        else:
            from PIL import Image
            image = np.asarray(Image.open(path).convert("L"))
    except (OSError, ValueError) as error:
        raise ClientError(f"cannot read {path}: {error}") from error
    if image.dtype != np.uint8 or image.ndim != 2:
        raise ClientError(f"{path}: need a 2-D 8-bit image, got {image.dtype} {image.shape}")
    return image


def _plan(args):
    dmd = DMDS[args.dmd]
    plan = schedule.plan(dmd, args.dclk, depth=args.depth, reset_mode=ResetMode[args.reset_mode],
                         order=PlaneOrder[args.order], exposure_s=args.exposure)
    return dmd, plan


def describe(plan):
    """What a register set reaches, from the schedule model: one line."""
    p = plan.params
    return (f"{plan.rate_hz:.1f} frames/s ({plan.frame_cycles} DCLK cycles per frame), "
            f"least significant plane {p.lsb} cycles ({p.lsb / plan.dclk_hz * 1e6:.2f} us), "
            f"set by {plan.binds}")


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m host", description=__doc__)
    parser.add_argument("--address", default="192.168.1.10", help="projector IPv4 address")
    parser.add_argument("--port", type=int, default=DEFAULT_PORT)
    parser.add_argument("--timeout", type=float, default=1.0, help="seconds to wait for a reply")
    sub = parser.add_subparsers(dest="command", required=True)
    send = sub.add_parser("send", help="send images as consecutive frames")
    send.add_argument("images", nargs="+", help=".npy or image files, 8-bit grey")
    send.add_argument("--frame", type=int, default=0, help="frame id of the first image")
    send.add_argument("--rate", type=float, default=100e6, help="pacing in bytes per second")
    configure = sub.add_parser("configure", help="plan a schedule, say the rate it reaches, send it")
    configure.add_argument("--dmd", default="dlp7000", choices=sorted(DMDS))
    configure.add_argument("--dclk", type=float, default=200e6, help="DCLK in Hz")
    configure.add_argument("--depth", type=int, default=8, help="bit-planes per frame, 1..8")
    configure.add_argument("--reset-mode", default="GLOBAL", choices=[m.name for m in ResetMode])
    configure.add_argument("--order", default="MSB_FIRST", choices=["MSB_FIRST", "LSB_FIRST"])
    configure.add_argument("--exposure", type=float, default=0.0,
                           help="least significant plane at least this long, seconds (0: shortest)")
    configure.add_argument("--dry-run", action="store_true", help="say the rate, send nothing")
    for name, text in (("arm", "let triggers reach the sequencer"), ("disarm", "ignore every trigger")):
        sub.add_parser(name, help=text)
    sub.add_parser("status", help="print the projector's counters")
    args = parser.parse_args(argv)

    try:
        if args.command == "configure":
            dmd, plan = _plan(args)
            print(f"{dmd.name}, {args.depth}-bit: {describe(plan)}")
            if args.dry_run:
                return 0
        with Client(args.address, args.port, timeout=args.timeout,
                    rate=getattr(args, "rate", None)) as client:
            if args.command == "send":
                images = [_load(path) for path in args.images]
                sent = client.send_sequence(images, args.frame)
                print(f"sent {len(images)} frame(s) in {sent} records")
            elif args.command == "configure":
                client.configure(plan, dmd)
                client.control(bit_depth=args.depth)
                print("sent; the sequencer takes it when no frame is playing")
            elif args.command in ("arm", "disarm"):
                client.control(armed=int(args.command == "arm"))
            else:
                for name, value in client.status().items():
                    print(f"{name:24} {value}")
    except (ClientError, ValueError) as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    return 0
