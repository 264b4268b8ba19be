"""Speed of the DLPC410 model and the camera model on full XGA, for planning system runs.

Figures are model cycles (or camera images) per wall second on the machine that runs the
benchmark: how much simulated DLPC410 time a cocotb or Amaranth run can afford to check.
"""

import time

import numpy as np

from sim.models import bitplane_model as bitplane
from sim.models.camera_model import Camera
from sim.models.dlpc410_driver import Driver, expand
from sim.models.dlpc410_model import Dlpc410
from spec.facts import DMDS

#: Where every figure here comes from (:mod:`flow.bench`): Python code timed on the host, not a
#: figure the models predict.
SOURCE = ("host: wall-clock speed of the Python DLPC410 model (sim.models.dlpc410_model) and camera model "
          "(sim.models.camera_model) on full XGA, on the machine running the bench")


def _rate(count, func):
    start = time.perf_counter()
    func()
    return count / (time.perf_counter() - start)


def model_speed(dmd="dlp7000", planes=8):
    """Per-cycle ``step`` rate over ``planes`` full-plane loads with global pulses between them,
    the idle-cycle rate, and the camera's image rate over the resulting history."""
    geometry = DMDS[dmd]
    model = Dlpc410(geometry, init_cycles=20)
    d = Driver(geometry)
    d.start(20)
    model.run(d.items)
    d.items.clear()
    image = np.random.default_rng(0).integers(0, 256, (geometry.rows, geometry.columns), dtype=np.uint8)
    bits = bitplane.planes(image)
    for k in range(planes):
        d.load(bits[k % 8])
        d.wait_until(d.cycle + model.rst_active_cycles + model.settle_cycles + 2)
        d.pulse("global")
        d.wait_until(d.cycle + model.rst_active_cycles + model.settle_cycles + 2)
    cycles = list(expand(d.items))
    row_rate = _rate(len(cycles), lambda: model.run(cycles))
    idle = {"arstz": 1}
    n_idle = 200_000
    idle_rate = _rate(n_idle, lambda: [model.step(idle) for _ in range(n_idle)])
    camera = Camera(model)
    n_images = 5
    image_rate = _rate(n_images, lambda: [camera.image(0, model.cycle) for _ in range(n_images)])
    return {"step_cycles_per_s": row_rate, "idle_cycles_per_s": idle_rate, "camera_images_per_s": image_rate}


def run():
    s = model_speed()
    return {
        "model.dlpc410_step_cycles_per_s_xga": (s["step_cycles_per_s"], "cycle/s"),
        "model.dlpc410_idle_cycles_per_s_xga": (s["idle_cycles_per_s"], "cycle/s"),
        "model.camera_images_per_s_xga_8_planes": (s["camera_images_per_s"], "image/s"),
    }


if __name__ == "__main__":
    for name, (value, unit) in run().items():
        print(f"{name} = {value:.4g} {unit}")
