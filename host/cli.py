"""Command line: ``python -m host send IMAGE...`` and ``python -m host status``."""

import argparse
import sys

import numpy as np

from .client import DEFAULT_PORT, Client, ClientError

__all__ = ["main"]


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
    sub.add_parser("status", help="print the projector's counters")
    args = parser.parse_args(argv)

    try:
        with Client(args.address, args.port, timeout=args.timeout,
                    rate=getattr(args, "rate", None)) as client:
            if args.command == "send":
                images = [_load(path) for path in args.images]
                sent = client.send_sequence(images, args.frame)
                print(f"sent {len(images)} frame(s) in {sent} records")
            else:
                for name, value in client.status().items():
                    print(f"{name:20} {value}")
    except ClientError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    return 0
