"""Offscreen rendering of the robot camera, headless through EGL.

The GL backend is the one MUJOCO_GL names, egl by default (set here and in sim/__init__
before mujoco is imported; a value already in the environment wins). The renderer makes
its own context for that backend instead of relying on the one mujoco picked when it
was first imported. EGL contexts do not survive fork: create renderers inside each
worker process (spawn). Mesa's llvmpipe compiles its shaders once per context, which makes
the first scene drawn in a fresh context about 0.2 s slower: a process that renders many
scenarios one after another (a sweep worker) keeps one RenderContext and lends it to each
renderer.
"""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")

from collections.abc import Sequence  # noqa: E402
from dataclasses import dataclass  # noqa: E402
from typing import Any  # noqa: E402

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from monopic.closing import Closing  # noqa: E402
from sim.world.scene import Scene
from sim.world.street import SURFACE_GROUP

GLContext = Any  # mujoco's egl/osmesa/glfw GLContext classes share no base class

DECOR = int(mujoco.mjtCatBit.mjCAT_DECOR)
GL_PACKAGES = ("libegl1", "libgl1-mesa-dri", "libegl-mesa0")


class GLUnavailableError(RuntimeError):
    """No OpenGL context could be made for offscreen rendering."""


@dataclass(frozen=True)
class Marker:
    """A sphere drawn on top of the scene for one render (tests, debugging)."""

    position: tuple[float, float, float]  # world frame, m
    radius: float = 0.03
    rgba: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 1.0)
    emissive: bool = True  # unlit, flat colour: easy to find in the image


def _gl_context(width: int, height: int) -> GLContext:
    """An offscreen OpenGL context for the backend MUJOCO_GL names (egl by default).

    Chosen here, at construction, rather than by mujoco at import time, so rendering
    works whatever imported mujoco first.
    """
    backend = os.environ.get("MUJOCO_GL", "egl").strip().lower()
    if backend == "egl":
        from mujoco.egl import GLContext as Context
    elif backend == "osmesa":
        from mujoco.osmesa import GLContext as Context
    else:
        from mujoco.glfw import GLContext as Context
    return Context(width, height)


def _unavailable(err: Exception) -> GLUnavailableError:
    backend = os.environ.get("MUJOCO_GL", "egl")
    return GLUnavailableError(
        f"cannot create an offscreen OpenGL context (MUJOCO_GL={backend!r}): {err}. "
        f"Install the EGL/Mesa packages: apt-get install {' '.join(GL_PACKAGES)}"
    )


class RenderContext(Closing):
    """An offscreen OpenGL context that renderers can use one after another.

    Images up to width x height; renderers given one borrow it and leave it open.
    """

    def __init__(self, width: int, height: int) -> None:
        self.width, self.height = width, height
        try:
            self._gl: GLContext | None = _gl_context(width, height)
        except Exception as err:  # ImportError, OSError, RuntimeError
            raise _unavailable(err) from err

    def fits(self, width: int, height: int) -> bool:
        return width <= self.width and height <= self.height

    def make_current(self) -> None:
        if self._gl is None:
            raise RuntimeError("render context used after close")
        self._gl.make_current()

    def close(self) -> None:
        if self._gl is not None:
            self._gl.free()
            self._gl = None


class KeptRenderContext(Closing):
    """One RenderContext lent to world after world (a sweep worker's runs, a dataset's),
    made again only when an image outgrows it."""

    def __init__(self) -> None:
        self.context: RenderContext | None = None

    def fitting(self, width: int, height: int) -> RenderContext:
        if self.context is None or not self.context.fits(width, height):
            self.close()
            self.context = RenderContext(width, height)
        return self.context

    def close(self) -> None:
        if self.context is not None:
            self.context.close()
            self.context = None


class SceneRenderer(Closing):
    """Renders the robot camera of a Scene at the camera model's image size.

    `context`, when given, is borrowed (and stays open after close); otherwise the
    renderer makes its own.
    """

    def __init__(
        self, scene: Scene, max_geom: int = 2000, context: RenderContext | None = None
    ) -> None:
        self.scene = scene
        cam = scene.camera
        self.width, self.height = cam.width, cam.height
        model = scene.model
        if context is not None and not context.fits(self.width, self.height):
            raise ValueError(
                f"a {context.width}x{context.height} render context cannot hold "
                f"{self.width}x{self.height} images"
            )
        self._own_context = context is None
        self._context = context or RenderContext(self.width, self.height)
        try:
            self._context.make_current()
            self._mjr = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100)
        except Exception as err:  # RuntimeError, mujoco.FatalError
            if self._own_context:
                self._context.close()
            raise _unavailable(err) from err
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._mjr)
        self._scene = mujoco.MjvScene(model, maxgeom=max_geom)
        self._rect = mujoco.MjrRect(0, 0, self.width, self.height)
        self._camera = mujoco.MjvCamera()
        self._camera.type = mujoco.mjtCamera.mjCAMERA_FIXED
        self._camera.fixedcamid = scene.robot.camera_id
        self._perturb = mujoco.MjvPerturb()
        self._option = mujoco.MjvOption()
        self._option.geomgroup[:] = [1, 1, 1, 0, 0, 0]  # hide the robot's own body
        self._option.sitegroup[:] = [0] * len(self._option.sitegroup)
        self._rgb = np.empty((self.height, self.width, 3), dtype=np.uint8)
        self._surfaces = frozenset(np.flatnonzero(model.geom_group == SURFACE_GROUP).tolist())

    def _no_shadows_from_surfaces(self) -> None:
        """Leave the surfaces flat on the ground out of the sun's shadow map.

        MuJoCo skips decor geoms when it draws the shadow map and only then; the colour
        passes draw them as before (street.SURFACE_GROUP says why).
        """
        geom, decor, surfaces = int(mujoco.mjtObj.mjOBJ_GEOM), DECOR, self._surfaces
        for g in self._scene.geoms[: self._scene.ngeom]:
            if g.objid in surfaces and g.objtype == geom:
                g.category = decor

    def _draw(self, markers: tuple[Marker, ...], segmentation: bool) -> np.ndarray:
        if self._mjr is None:
            raise RuntimeError("render called after close")
        self._context.make_current()
        # Bind this renderer's own offscreen buffer: another renderer sharing the context
        # may have drawn since, and would otherwise receive this draw.
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self._mjr)
        mujoco.mjv_updateScene(
            self.scene.model,
            self.scene.data,
            self._option,
            self._perturb,
            self._camera,
            mujoco.mjtCatBit.mjCAT_ALL,
            self._scene,
        )
        self._no_shadows_from_surfaces()
        for marker in markers:
            _add_marker(self._scene, marker)
        self._scene.flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = segmentation
        self._scene.flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = segmentation
        mujoco.mjr_render(self._rect, self._scene, self._mjr)
        mujoco.mjr_readPixels(self._rgb, None, self._rect, self._mjr)
        return np.flipud(self._rgb)  # OpenGL rows run bottom-up

    def render(self, markers: tuple[Marker, ...] = ()) -> np.ndarray:
        """The current robot-camera image, RGB uint8 (height, width, 3)."""
        return self._draw(markers, segmentation=False).copy()

    def mask(self, geoms: np.ndarray) -> np.ndarray:
        """Boolean (height, width) mask of the pixels where any of `geoms` is visible
        (a body's geoms: Scene.geoms_of)."""
        return self.masks([geoms])[0]

    def masks(self, bodies: Sequence[np.ndarray]) -> list[np.ndarray]:
        """One boolean (height, width) mask per body (its geoms), from one render.

        Uses MuJoCo's segmentation rendering (each drawn geom in its own colour), so
        occluders hide a body as they do in the colour image.
        """
        image = self._draw((), segmentation=True).astype(np.int64)
        segid = image[..., 0] + (image[..., 1] << 8) + (image[..., 2] << 16)  # 0: none
        segid = np.clip(segid, 0, self._scene.ngeom)
        owner = np.full(self.scene.model.ngeom, -1)  # geom id -> body index
        for b, geoms in enumerate(bodies):
            owner[np.asarray(geoms, dtype=int)] = b
        lookup = np.full(self._scene.ngeom + 1, -1)  # segmentation id + 1 -> body index
        for k in range(self._scene.ngeom):
            g = self._scene.geoms[k]
            if g.segid >= 0 and g.objtype == mujoco.mjtObj.mjOBJ_GEOM:
                lookup[g.segid + 1] = owner[g.objid]
        body_of = lookup[segid]
        return [body_of == b for b in range(len(bodies))]

    def close(self) -> None:
        """Free the GL resources; the renderer cannot be used afterwards."""
        if self._mjr is not None:
            self._mjr.free()
            self._mjr = None
            if self._own_context:
                self._context.close()


def _add_marker(scene: mujoco.MjvScene, marker: Marker) -> None:
    if scene.ngeom >= scene.maxgeom:
        raise RuntimeError("no room left in the MuJoCo scene for another marker")
    geom = scene.geoms[scene.ngeom]
    mujoco.mjv_initGeom(
        geom,
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        size=np.array([marker.radius, 0.0, 0.0]),
        pos=np.asarray(marker.position, dtype=float),
        mat=np.eye(3).reshape(-1),
        rgba=np.asarray(marker.rgba, dtype=np.float32),
    )
    if marker.emissive:
        geom.emission = 1.0
        geom.specular = 0.0
    geom.category = int(mujoco.mjtCatBit.mjCAT_DECOR)
    scene.ngeom += 1
