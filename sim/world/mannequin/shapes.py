"""The shapes of a mannequin's geoms, kept so a frame only has to turn them.

Ground truth needs, every frame, points on the pedestrian's surface (its apparent box),
its highest point, and the lowest point of its shoes (to stand it on the ground). The
mannequin is built from spheres, capsules, ellipsoids and boxes only, so all three are
closed-form and vectorised over the geoms here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

# As plain ints: comparing an array with MuJoCo's enum objects goes element by element
# through Python (70 us for 44 geoms).
SPHERE = int(mujoco.mjtGeom.mjGEOM_SPHERE)
CAPSULE = int(mujoco.mjtGeom.mjGEOM_CAPSULE)
ELLIPSOID = int(mujoco.mjtGeom.mjGEOM_ELLIPSOID)
BOX = int(mujoco.mjtGeom.mjGEOM_BOX)
SURFACE_KINDS = (SPHERE, CAPSULE, ELLIPSOID, BOX)


def _geom_kinds(model: mujoco.MjModel, geoms: np.ndarray, purpose: str) -> np.ndarray:
    """The geoms' types, checked to be ones the vectorised helpers here handle."""
    kind = model.geom_type[geoms]
    bad = ~(kind[:, None] == np.array(SURFACE_KINDS, dtype=int)).any(axis=1)
    if bad.any():
        raise ValueError(f"unsupported geom type {kind[bad][0]} for {purpose}")
    return kind


def _unit_sphere(n: int) -> np.ndarray:
    """n roughly even directions on the unit sphere (Fibonacci lattice)."""
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    r = np.sqrt(1 - z * z)
    phi = i * math.pi * (3 - math.sqrt(5))
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


@dataclass(frozen=True)
class GeomShapes:
    """Some geoms' shapes, read once from the model (spheres, capsules, ellipsoids, boxes).

    Ground truth asks every frame for the mannequin's surface points (its apparent box)
    and its height; with the shapes kept, a frame only turns them by the geoms' poses
    (1.9 of the 5.2 ms a human walker's truth took a frame when they were rebuilt).
    """

    geoms: np.ndarray
    kind: np.ndarray
    size: np.ndarray  # (G, 3) MuJoCo geom sizes
    local: np.ndarray  # (G, n, 3) surface points in each geom's own frame

    @classmethod
    def of(cls, model: mujoco.MjModel, geoms: np.ndarray, n: int = 98) -> GeomShapes:
        kind = _geom_kinds(model, geoms, "surface points and z extents")
        size = model.geom_size[geoms].copy()
        dirs = _unit_sphere(n)
        round_ = (kind == SPHERE) | (kind == CAPSULE)
        # Spheres and capsules scale the directions by the radius, ellipsoids and boxes per
        # axis; a capsule's hemispheres sit its half-length along its z.
        scale = np.where(round_[:, None], size[:, :1], size[:, :3])  # (G, 3)
        shape = np.where((kind == BOX)[:, None, None], np.sign(dirs)[None], dirs[None])
        local = shape * scale[:, None, :]  # (G, n, 3)
        capsule = kind == CAPSULE
        local[capsule, :, 2] += np.sign(dirs[:, 2])[None, :] * size[capsule, 1][:, None]
        return cls(np.asarray(geoms), kind, size, local)

    def surface_points(self, data: mujoco.MjData) -> np.ndarray:
        """World points (G * n, 3) on the geoms' surfaces, geom by geom."""
        rot = data.geom_xmat[self.geoms].reshape(-1, 3, 3)
        world = data.geom_xpos[self.geoms][:, None, :] + self.local @ rot.transpose(0, 2, 1)
        return world.reshape(-1, 3)

    def z_extent(self, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        """Lowest and highest world z of each geom."""
        centre = data.geom_xpos[self.geoms, 2]
        zrow = data.geom_xmat[self.geoms].reshape(-1, 3, 3)[:, 2, :]  # world z of local axes
        kind, size = self.kind, self.size
        half = np.zeros(len(self.geoms))
        sphere, capsule = kind == SPHERE, kind == CAPSULE
        ellipsoid, box = kind == ELLIPSOID, kind == BOX
        half[sphere] = size[sphere, 0]
        half[capsule] = size[capsule, 0] + np.abs(zrow[capsule, 2]) * size[capsule, 1]
        half[ellipsoid] = np.linalg.norm(size[ellipsoid] * zrow[ellipsoid], axis=1)
        half[box] = np.abs(size[box] * zrow[box]).sum(axis=1)
        return centre - half, centre + half


def geom_z_extent(
    model: mujoco.MjModel, data: mujoco.MjData, geoms: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Lowest and highest world z of each geom (spheres, capsules, ellipsoids, boxes)."""
    return GeomShapes.of(model, geoms, n=1).z_extent(data)
