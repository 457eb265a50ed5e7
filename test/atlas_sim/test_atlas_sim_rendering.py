"""Offscreen rendering to PNG.

MuJoCo chooses its GL backend when first imported, so rendering runs in a
subprocess with ``MUJOCO_GL`` set; EGL is tried first, then OSMesa.  The test
is skipped only if no backend can render at all.
"""

import os
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

from atlas_sim.simulator.rendering import encode_png

pytestmark = pytest.mark.mujoco

REPO = Path(__file__).resolve().parents[2]
WIDTH, HEIGHT = 320, 240

RENDER_SCRIPT = f"""
import sys
from atlas_sim.simulator import AtlasSimulator, KeyFrameRecorder
sim = AtlasSimulator()
recorder = KeyFrameRecorder(sim, sys.argv[1], width={WIDTH}, height={HEIGHT})
sim.execute("stand")
sim.execute("look_down")
recorder.capture("final")
recorder.close()
# a renderer sizes its buffers to its frames but leaves the model as it was: a bigger one still fits
from atlas_sim.simulator import FrameRenderer
assert (sim.physics.model.vis.global_.offwidth, sim.physics.model.vis.global_.offheight) == (1280, 960)
with FrameRenderer(sim, 640, 480) as big:
    big.save(sys.argv[1] + "/big.png")
"""


def decode_png(data: bytes) -> np.ndarray:
    """Minimal decoder for the 8-bit RGB, unfiltered PNGs written by encode_png."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    position, idat, header = 8, b"", None
    while position < len(data):
        (length,) = struct.unpack(">I", data[position : position + 4])
        kind = data[position + 4 : position + 8]
        payload = data[position + 8 : position + 8 + length]
        (crc,) = struct.unpack(">I", data[position + 8 + length : position + 12 + length])
        assert crc == zlib.crc32(kind + payload) & 0xFFFFFFFF
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", payload)
        elif kind == b"IDAT":
            idat += payload
        position += 12 + length
    width, height, depth, color_type = header[:4]
    assert (depth, color_type) == (8, 2)
    rows = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(height, 1 + 3 * width)
    assert not rows[:, 0].any()  # filter type 0 on every scanline
    return rows[:, 1:].reshape(height, width, 3)


def test_png_encoder_round_trips():
    image = np.random.default_rng(0).integers(0, 256, size=(7, 5, 3), dtype=np.uint8)
    assert np.array_equal(decode_png(encode_png(image)), image)


def render_with_any_backend(directory: Path) -> str:
    errors = []
    for backend in ("egl", "osmesa"):
        env = dict(os.environ, MUJOCO_GL=backend, PYTHONPATH=str(REPO))
        run = subprocess.run(
            [sys.executable, "-c", RENDER_SCRIPT, str(directory / backend)],
            cwd=REPO, env=env, capture_output=True, text=True, timeout=120,
        )
        if run.returncode == 0:
            return backend
        errors.append(f"{backend}: {run.stderr.strip().splitlines()[-1:]}")
    # make test installs the EGL libraries (Makefile system-packages), so not rendering is a defect.
    pytest.fail(f"no OpenGL backend can render here (install libegl1 libegl-mesa0): {errors}")


def test_key_frames_are_rendered_to_png(tmp_path):
    backend = render_with_any_backend(tmp_path)
    frames = sorted(path for path in (tmp_path / backend).glob("*.png") if path.name != "big.png")
    names = [f.name for f in frames]
    # started + finished for stand and look_down, plus the manual capture
    assert len(frames) == 5, names
    assert "stand_started" in names[0] and "look_down_completed" in names[3] and "final" in names[4]
    image = decode_png(frames[-1].read_bytes())
    assert image.shape == (HEIGHT, WIDTH, 3)
    assert image.std() > 10  # a real scene, not a blank frame
    first = decode_png(frames[0].read_bytes())
    assert np.abs(first.astype(int) - image.astype(int)).mean() > 1  # the robot moved
    assert decode_png((tmp_path / backend / "big.png").read_bytes()).shape == (480, 640, 3)
