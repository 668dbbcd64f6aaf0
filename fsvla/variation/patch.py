"""The V4 patch in the scene: where it sits, what it shows. Imports no simulator.

A V4 :class:`~fsvla.variation.vision.Patch` is a square, render-only quad fixed to a body
of the scene, so it moves with that body and every camera sees it with perspective and
occlusion; it has no collision shape and no mass. :func:`mount_patch` decides where the
quad sits from the layout alone (the scene spec), in the frame of the body that carries
it, as a :class:`PatchMount`; :func:`patch_corners` gives its four corners in the world
for any pose of that body. ``face`` places it:

- ``front`` (the default): upright on the side of the entity's bounding box that faces
  the front camera, standing on the entity's base (centred on the side when the entity is
  taller than the patch); carried with the entity;
- ``top``: flat on the top of the entity's bounding box, its image's top edge away from
  the front camera; carried with the entity;
- ``beside``: flat on the entity's support (the table), just outside its side that faces
  the front camera; carried with the support, not with the entity.

A hazard zone counts as its footprint, a flat plate :data:`ZONE_THICKNESS` thick. "The
front camera" is the world-mounted camera named ``front``, else the first world-mounted
camera; the side is chosen once, at the layout's poses, and then stays on the body.

The patch's pixels come from a PNG file (:func:`load_patch_image`, what ``fsvla run
--patch`` names) or from :func:`patch_pixels`, a seeded library of high-saliency
patterns. The corners are ordered as the image's: top-left, top-right, bottom-right,
bottom-left, so pixel (0, 0) lies at corner 0 and the image is seen unmirrored from the
quad's front (its normal is ``(c1 - c0) x (c0 - c3)``). ``fsvla attack`` composites a patch
into rendered frames with the homography from the image's corners to the projected ones.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict

from fsvla.compiler.pose import quat_to_matrix, transform_points
from fsvla.compiler.scene import SceneSpec
from fsvla.world import PoseReading

from .vision import Patch

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]

#: How far the quad stands off the surface it is on (m): above it, so it never flickers.
PATCH_LIFT = 0.002
#: The gap between an entity's side and a patch ``beside`` it (m).
BESIDE_GAP = 0.01
#: The thickness a hazard zone's marker is taken to have (m).
ZONE_THICKNESS = 0.003
#: The side, in pixels, of a generated patch image.
PATCH_PIXELS = 128
#: The patterns :func:`patch_pixels` draws from.
PATCH_PATTERNS = ("blocks", "checker", "rings", "sunburst")


class PatchFileError(ValueError):
    """A patch file that cannot be used; the message names the file."""


class PatchMount(BaseModel):
    """Where one patch sits: on ``body`` (a body, an articulated body's root, or a zone),
    its corners in that body's frame (image order: top-left, top-right, bottom-right,
    bottom-left), and the body's pose in the layout."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    body: str
    corners: tuple[Vec3, Vec3, Vec3, Vec3]
    body_position: Vec3
    body_quaternion: Quat

    def normal(self) -> NDArray[np.float64]:
        """The unit normal of the quad's front, in the body's frame."""
        c = np.asarray(self.corners)
        n = np.cross(c[1] - c[0], c[0] - c[3])
        return n / np.linalg.norm(n)


def patch_corners(mount: PatchMount, body_pose: PoseReading | None = None) -> NDArray[np.float64]:
    """The patch's four corners (4 × 3, world frame, image order) when its body is at
    ``body_pose`` (default: where the layout put it; a zone never moves). For a running
    scene, pass ``state.body_pose(mount.body)`` (:class:`fsvla.world.SceneState`)."""
    if body_pose is None:
        return transform_points(mount.corners, mount.body_position, mount.body_quaternion)
    return transform_points(mount.corners, np.asarray(body_pose.p, dtype=np.float64),
                            np.asarray(body_pose.q, dtype=np.float64))


def mount_patch(spec: SceneSpec, patch: Patch) -> PatchMount:
    """Where ``patch`` sits in the scene of ``spec`` (see the module doc); ValueError when
    the scene has no body or zone ``patch.target``, or when a patch ``beside`` it has
    nothing to lie on."""
    lo, hi, position, quaternion = _box(spec, patch.target)
    rotation = quat_to_matrix(quaternion)
    toward = rotation.T @ (_front_eye(spec) - transform_points([(lo + hi) / 2], position,
                                                               quaternion)[0])
    half = patch.size / 2.0
    if patch.face == "top":
        normal = np.array([0.0, 0.0, 1.0])
        up = -np.array([toward[0], toward[1], 0.0])
        up = up / np.linalg.norm(up) if np.linalg.norm(up) > 1e-9 else np.array([1.0, 0.0, 0.0])
        centre = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2] + PATCH_LIFT])
        return _mount(patch.target, centre, up, normal, half, position, quaternion)
    axis = _facing_axis(toward)
    k = int(np.argmax(np.abs(axis)))
    side = hi[k] if axis[k] > 0 else lo[k]
    if patch.face == "front":
        centre = (lo + hi) / 2
        centre[k] = side + axis[k] * PATCH_LIFT
        centre[2] = max(centre[2], lo[2] + half)
        return _mount(patch.target, centre, np.array([0.0, 0.0, 1.0]), axis, half,
                      position, quaternion)
    support = _support(spec, patch.target)
    centre = (lo + hi) / 2
    centre[k] = side + axis[k] * (BESIDE_GAP + half)
    centre[2] = lo[2] + PATCH_LIFT
    local = _corners(centre, -axis, np.array([0.0, 0.0, 1.0]), half)
    world = transform_points(local, position, quaternion)
    _, _, s_position, s_quaternion = _box(spec, support)
    in_support = (world - np.asarray(s_position)) @ quat_to_matrix(s_quaternion)
    return PatchMount(body=support, corners=_tuple4(in_support),
                      body_position=s_position, body_quaternion=s_quaternion)


def patch_pixels(seed: int, size: int = PATCH_PIXELS) -> NDArray[np.uint8]:
    """A ``size`` × ``size`` RGB pattern of saturated, high-contrast colours, drawn from
    :data:`PATCH_PATTERNS` by ``seed`` (blocks of random colours, a checkerboard, concentric
    rings, a sunburst); the same seed gives the same pixels everywhere."""
    rng = np.random.default_rng(seed)
    pattern = PATCH_PATTERNS[int(rng.integers(len(PATCH_PATTERNS)))]
    palette = _palette(rng)
    y, x = (np.mgrid[0:size, 0:size].astype(np.float64) + 0.5) / size
    if pattern == "blocks":
        n = int(rng.integers(4, 9))
        index = rng.integers(0, len(palette), size=(n, n))
        chosen = index[np.minimum((y * n).astype(int), n - 1), np.minimum((x * n).astype(int), n - 1)]
    elif pattern == "checker":
        n = int(rng.integers(3, 8))
        chosen = ((np.floor(x * n) + np.floor(y * n)) % 2).astype(int)
    elif pattern == "rings":
        r = np.hypot(x - 0.5, y - 0.5)
        chosen = (np.floor(r * 2 * int(rng.integers(3, 7))) % 2).astype(int)
    else:
        angle = np.arctan2(y - 0.5, x - 0.5) + float(rng.uniform(0, np.pi))
        chosen = (np.floor(angle / np.pi * int(rng.integers(4, 10))) % 2).astype(int)
    return palette[chosen % len(palette)]


def load_patch_image(path: str | Path) -> NDArray[np.uint8]:
    """The RGB pixels (H × W × 3) of the PNG file ``path``; :class:`PatchFileError` when it
    does not exist or is not a PNG image. A transparent pixel is shown as it is coloured:
    the patch is opaque."""
    file = Path(path)
    if not file.is_file():
        raise PatchFileError(f"patch file {file}: no such file")
    try:
        from PIL import Image, UnidentifiedImageError
    except ImportError as err:  # pragma: no cover - pillow comes with fsvla[sim]
        raise PatchFileError(f"patch file {file}: reading a PNG needs pillow ({err})") from None
    try:
        with Image.open(file) as image:
            if image.format != "PNG":
                raise PatchFileError(f"patch file {file}: not a PNG image "
                                     f"({image.format or 'unknown format'})")
            pixels = np.asarray(image.convert("RGB"), dtype=np.uint8)
    except (UnidentifiedImageError, OSError) as err:
        raise PatchFileError(f"patch file {file}: not a PNG image ({err})") from None
    if min(pixels.shape[:2]) < 1:
        raise PatchFileError(f"patch file {file}: the image is empty")
    return pixels


# --- pieces -----------------------------------------------------------------------------


def _palette(rng: np.random.Generator) -> NDArray[np.uint8]:
    """Two to four saturated colours, the first two far apart (a strong edge)."""
    base = np.array([[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 0], [255, 0, 255],
                     [0, 255, 255], [255, 255, 255], [0, 0, 0]], dtype=np.uint8)
    first = int(rng.integers(len(base)))
    second = (first + len(base) // 2 + int(rng.integers(-1, 2))) % len(base)
    rest = rng.permutation([i for i in range(len(base)) if i not in (first, second)])
    return base[[first, second, *rest[:int(rng.integers(0, 3))]]]


def _box(spec: SceneSpec, name: str) -> tuple[NDArray[np.float64], NDArray[np.float64], Vec3, Quat]:
    """An entity's bounding box (low and high corners, its own frame) and its layout pose."""
    body = next((b for b in spec.bodies if b.name == name), None)
    if body is not None:
        bounds = body.asset.bounds
        c, h = np.asarray(bounds.center), np.asarray(bounds.half_extents)
        return c - h, c + h, body.pose.position, body.pose.quaternion
    zone = next((z for z in spec.zones if z.name == name), None)
    if zone is not None:
        footprint = zone.marker.footprint
        lo = np.array([*footprint.min_xy, 0.0])
        hi = np.array([*footprint.max_xy, ZONE_THICKNESS])
        return lo, hi, zone.pose.position, zone.pose.quaternion
    names = [b.name for b in spec.bodies] + [z.name for z in spec.zones]
    raise ValueError(f"a patch on {name!r}: the scene {spec.scenario!r} has no body or zone "
                     f"of that name (it has {', '.join(names)})")


def _support(spec: SceneSpec, name: str) -> str:
    entity = next(e for e in (*spec.bodies, *spec.zones) if e.name == name)
    if entity.support == "world":
        raise ValueError(f"a patch beside {name!r}: it stands on the floor, which has nothing "
                         "to carry the patch; put the patch on its front or top")
    return entity.support


def _front_eye(spec: SceneSpec) -> NDArray[np.float64]:
    """Where the front camera is (a point far along +x when the scene has none)."""
    world = [c for c in spec.cameras if c.parent == "world"]
    camera = next((c for c in world if c.name == "front"), world[0] if world else None)
    return np.asarray(camera.pose.position if camera is not None else (10.0, 0.0, 0.0))


def _facing_axis(toward: NDArray[np.float64]) -> NDArray[np.float64]:
    """Of the box's four upright sides' outward normals (±x, ±y), the one most toward
    ``toward`` (a +x tie wins)."""
    axes = np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0]])
    return axes[int(np.argmax(axes @ toward))]


def _corners(centre: NDArray[np.float64], up: NDArray[np.float64], normal: NDArray[np.float64],
             half: float) -> NDArray[np.float64]:
    right = np.cross(up, normal)
    return np.array([centre - right * half + up * half, centre + right * half + up * half,
                     centre + right * half - up * half, centre - right * half - up * half])


def _mount(body: str, centre: NDArray[np.float64], up: NDArray[np.float64],
           normal: NDArray[np.float64], half: float, position: Vec3, quaternion: Quat) -> PatchMount:
    return PatchMount(body=body, corners=_tuple4(_corners(centre, up, normal, half)),
                      body_position=position, body_quaternion=quaternion)


def _tuple4(points: NDArray[np.float64]) -> tuple[Vec3, Vec3, Vec3, Vec3]:
    return tuple(tuple(float(v) for v in p) for p in points)  # type: ignore[return-value]


__all__ = ["BESIDE_GAP", "PATCH_LIFT", "PATCH_PATTERNS", "PATCH_PIXELS", "ZONE_THICKNESS",
           "PatchFileError", "PatchMount", "load_patch_image", "mount_patch", "patch_corners",
           "patch_pixels"]
