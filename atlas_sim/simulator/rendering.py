"""Offscreen rendering of the simulator to PNG files.

MuJoCo picks its OpenGL backend from ``MUJOCO_GL`` when it is *first
imported*, so headless programs must set it before importing anything that
imports mujoco (``atlas_sim.simulator.physics``, ``atlas_sim.simulator.atlas_simulator``)::

    import os
    os.environ.setdefault("MUJOCO_GL", "egl")   # or "osmesa"
    from atlas_sim.simulator import AtlasSimulator, FrameRenderer

The PNG encoder below is a small self-contained writer (zlib + CRC chunks), so
no imaging library is needed.
"""

from __future__ import annotations

import re
import struct
import zlib
from pathlib import Path
from typing import List, Union

import numpy as np

PathLike = Union[str, Path]


def encode_png(image: np.ndarray) -> bytes:
    """Encode an ``(height, width, 3)`` uint8 RGB array as PNG bytes."""
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"expected an (h, w, 3) RGB image, got shape {image.shape}")
    pixels = np.ascontiguousarray(image, dtype=np.uint8)
    height, width, _ = pixels.shape
    # Every scanline starts with filter type 0 (no filter).
    scanlines = np.concatenate([np.zeros((height, 1), np.uint8), pixels.reshape(height, -1)], axis=1)

    def chunk(kind: bytes, payload: bytes) -> bytes:
        body = kind + payload
        return struct.pack(">I", len(payload)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)  # 8-bit RGB
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(scanlines.tobytes(), 6))
        + chunk(b"IEND", b"")
    )


def save_png(path: PathLike, image: np.ndarray) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(encode_png(image))
    return path


#: Side of the shadow map in pixels (MuJoCo's default 4096).
SHADOW_MAP_SIZE = 2048
#: Geoms one frame can draw: the scene has ~25 (MuJoCo's default room for 10,000 took ~9 MiB).
MAX_SCENE_GEOMS = 1000


class FrameRenderer:
    """Renders the current frame of a simulator (or ``HumanoidPhysics``).

    ``camera`` is a camera name of the model: ``follow`` (rides with the pelvis
    from the front-right, so the robot stays centred), ``overview`` (fixed, turns
    to the pelvis) or ``head_camera`` (what the robot sees). ``plain`` drops shadows,
    reflections and multisampling: in software GL a 480x360 frame took 13 ms instead of 190 ms,
    which is what lets a run be filmed at robot speed.
    """

    def __init__(self, simulator, width: int = 640, height: int = 480, camera: str = "follow",
                 plain: bool = False):
        import mujoco  # local: only rendering users need a GL context

        self.physics = getattr(simulator, "physics", simulator)
        self.camera = camera
        self.plain = plain
        # In software GL the model's offscreen buffer (1280x960, multisampled) and MuJoCo's
        # 4096^2 shadow map took ~110 MiB; a buffer of the frame's size renders the same
        # pixels, and a 2048^2 shadow map looks the same at these sizes. The model is left as it was.
        visual = self.physics.model.vis
        kept = (visual.global_.offwidth, visual.global_.offheight, visual.quality.shadowsize,
                visual.quality.offsamples)
        visual.global_.offwidth, visual.global_.offheight = width, height
        visual.quality.shadowsize = min(visual.quality.shadowsize, SHADOW_MAP_SIZE)
        if plain:
            visual.quality.offsamples = 0
        try:
            self._renderer = mujoco.Renderer(self.physics.model, height=height, width=width,
                                             max_geom=MAX_SCENE_GEOMS)
        finally:
            (visual.global_.offwidth, visual.global_.offheight, visual.quality.shadowsize,
             visual.quality.offsamples) = kept
        self._plain_flags = (mujoco.mjtRndFlag.mjRND_SHADOW, mujoco.mjtRndFlag.mjRND_REFLECTION)

    def render(self) -> np.ndarray:
        """The current frame as an ``(height, width, 3)`` uint8 array."""
        self._renderer.update_scene(self.physics.data, camera=self.camera)
        if self.plain:
            for flag in self._plain_flags:
                self._renderer.scene.flags[flag] = 0
        return self._renderer.render()

    def save(self, path: PathLike) -> Path:
        return save_png(path, self.render())

    def close(self) -> None:
        self._renderer.close()

    def __enter__(self) -> "FrameRenderer":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


#: Frames per second of robot time that ``KeyFrameRecorder.capture_motion`` keeps (>= 15: motion,
#: not a slideshow; issue 35).
MOTION_FPS = 16


class KeyFrameRecorder:
    """Saves a PNG whenever a request starts or finishes (the key moments), and, through
    ``capture_motion``, every ``1 / motion_fps`` seconds of robot time in between.

    Files are named ``<index>_<robot time>s_<label>.png`` in ``directory`` (the robot time
    with three decimals, e.g. ``0042_0002.625s_motion.png``; key moments are labelled
    ``<capability>_<event>``); ``paths`` lists them in order and ``times`` their robot times.
    Call ``capture(label)`` for extra frames and ``close()`` when done.
    """

    def __init__(self, simulator, directory: PathLike, width: int = 640, height: int = 480,
                 camera: str = "follow", motion_fps: float = MOTION_FPS):
        self.simulator = simulator
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        # filmed motion is drawn plain (fast enough for robot speed), the key moments alike so
        # that the frames of one run look the same
        self.renderer = FrameRenderer(simulator, width, height, camera, plain=motion_fps > 0)
        self.paths: List[Path] = []
        self.times: List[float] = []
        self.motion_period = 1.0 / motion_fps if motion_fps > 0 else None
        self._next_motion_frame: float | None = None
        simulator.add_listener(self._on_event)

    def _on_event(self, event: str, request) -> None:
        label = event if event == "started" else request.result.outcome
        self.capture(f"{request.name}_{label}")

    def capture(self, label: str) -> Path:
        safe = re.sub(r"[^A-Za-z0-9_.-]+", "_", label)
        time = self.simulator.time
        name = f"{len(self.paths):04d}_{time:08.3f}s_{safe}.png"
        path = self.renderer.save(self.directory / name)
        self.paths.append(path)
        self.times.append(round(time, 3))
        return path

    def capture_motion(self) -> None:
        """A ``motion`` frame when ``1 / motion_fps`` robot seconds passed since the last one
        (call it every control tick; frames land on multiples of the period)."""
        if self.motion_period is None:
            return
        time = self.simulator.time
        if self._next_motion_frame is None:  # the first, unless a key frame shows this moment already
            self._next_motion_frame = time if not self.times or self.times[-1] < time - 1e-9 \
                else time + self.motion_period
        if time + 1e-9 >= self._next_motion_frame:
            self.capture("motion")
            periods = int((time - self._next_motion_frame) / self.motion_period + 1e-9) + 1
            self._next_motion_frame += periods * self.motion_period

    def close(self) -> None:
        self.simulator.remove_listener(self._on_event)
        self.renderer.close()
