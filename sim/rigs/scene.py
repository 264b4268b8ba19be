"""The default scene: a small bright target moving over a structured background.

What a hardware-in-the-loop user sends: a thermal-like background (gradients, a grid of
features, low-contrast texture) with a hot target that moves from frame to frame.
"""

import numpy as np

__all__ = ["default_scene"]


def default_scene(frames, rows=768, columns=1024, seed=0):
    """``frames`` uint8 images of ``rows`` x ``columns``."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:rows, 0:columns].astype(np.float64)
    background = 40 + 50 * (xx / columns) + 30 * (yy / rows)            # sky-to-ground gradient
    background += 12 * np.sin(2 * np.pi * xx / 97) * np.cos(2 * np.pi * yy / 61)  # structure
    background += 25 * (((xx // 64) + (yy // 64)) % 2)                  # a grid of features
    texture = rng.normal(0, 3, (rows, columns))
    images = []
    for f in range(frames):
        cx = columns * (0.2 + 0.6 * f / max(1, frames - 1))
        cy = rows * (0.5 + 0.25 * np.sin(f / 3))
        r2 = (xx - cx) ** 2 + (yy - cy) ** 2
        target = 255 * np.exp(-r2 / (2 * (min(rows, columns) / 80) ** 2))
        image = np.clip(np.maximum(background + texture, target), 0, 255)
        images.append(np.rint(image).astype(np.uint8))
    return images


def main(argv=None):
    """``python -m sim.rigs.scene scene.png [rows columns]``: the scene's first frame as a PNG, for
    the host quick start (the virtual projector is 96 x 128)."""
    import argparse

    from PIL import Image

    parser = argparse.ArgumentParser(prog="python -m sim.rigs.scene", description=main.__doc__)
    parser.add_argument("path")
    parser.add_argument("rows", type=int, nargs="?", default=96)
    parser.add_argument("columns", type=int, nargs="?", default=128)
    args = parser.parse_args(argv)
    Image.fromarray(default_scene(1, args.rows, args.columns)[0]).save(args.path)
    print(f"wrote {args.path}: {args.rows} x {args.columns}, 8-bit grey")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
