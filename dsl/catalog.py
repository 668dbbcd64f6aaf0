"""The vocabulary the language knows: assets, hazard kinds, metrics, predicates,
base tasks and embodiments, each with the parameters it takes.

This module is plain data. The checker validates a scenario against it; the
compiler implements every entry (an asset builder per asset kind, a channel per
metric), and its tests assert that nothing listed here is left unimplemented.
"""

from __future__ import annotations

from enum import Enum
from typing import Union

from pydantic import BaseModel, ConfigDict

from .units import Dimension

Scalar = Union[float, int, str, bool]
Value = Union[Scalar, tuple[float, ...]]


class Param(BaseModel):
    """One named parameter of an asset, hazard or predicate."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    name: str
    dimension: Dimension = Dimension.NUMBER
    arity: int = 1  # 1 for a scalar, 2 or 3 for a tuple such as size=(18 cm, 18 cm)
    default: Value | None = None  # in SI units; None with required=False means "absent"
    required: bool = False
    minimum: float | None = None  # inclusive, SI, applied to every component
    maximum: float | None = None
    choices: tuple[str, ...] | None = None  # a symbolic value such as side=front
    integer: bool = False
    path: bool = False  # a file path, resolved relative to the .fsv file
    doc: str = ""


class AssetClass(str, Enum):
    RIGID = "rigid"  # a procedural rigid body
    ARTICULATED = "articulated"  # generated from a URDF template
    FILE = "file"  # a mesh or URDF file next to the scenario
    ZONE = "zone"  # a region with no body (heat zone, no-go region, corridor)


class AssetKind(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")

    name: str
    asset_class: AssetClass
    params: tuple[Param, ...]
    doc: str
    support: bool = False  # other objects may stand on it
    container: bool = False  # objects may be put inside it
    parts: tuple[str, ...] = ()  # articulated parts that predicates can name

    def param(self, name: str) -> Param | None:
        return next((p for p in self.params if p.name == name), None)

    def param_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.params)


def _length(name: str, default: float | None, lo: float = 0.001, hi: float = 2.0, **kw) -> Param:
    return Param(name=name, dimension=Dimension.LENGTH, default=default, minimum=lo, maximum=hi, **kw)


def _size2(default: tuple[float, float], lo: float = 0.005, hi: float = 2.0) -> Param:
    return Param(name="size", dimension=Dimension.LENGTH, arity=2, default=default, minimum=lo, maximum=hi)


def _size3(default: tuple[float, float, float], lo: float = 0.005, hi: float = 2.0) -> Param:
    return Param(name="size", dimension=Dimension.LENGTH, arity=3, default=default, minimum=lo, maximum=hi)


#: How far an articulated body's part starts open: a fraction of its joint's range.
_OPEN = Param(name="open", minimum=0.0, maximum=1.0,
              doc="how far the part starts open, as a fraction of its range (0: shut, 1: fully open)")
_MASS = Param(name="mass", dimension=Dimension.MASS, minimum=0.001, maximum=50.0,
              doc="overrides the mass computed from the asset's density")
_FRICTION = Param(name="friction", default=0.6, minimum=0.0, maximum=2.0)
#: Colours a movable body can be given by name (the instruction's "the blue block" must
#: be what the camera sees); the compiler holds their RGB values.
COLOR_NAMES = ("red", "green", "blue", "yellow", "orange", "purple", "pink", "brown",
               "white", "grey", "black")
_BODY_COLOR = Param(name="color", choices=COLOR_NAMES,
               doc="the body's colour by name (default: its material's own look)")

_ASSETS: list[AssetKind] = [
    AssetKind(name="table", asset_class=AssetClass.RIGID, support=True,
              doc="the work surface; declared implicitly with the defaults when a scenario omits it",
              params=(_size2((1.2, 0.8), lo=0.3, hi=3.0), _length("height", 0.75, lo=0.3, hi=1.2), _FRICTION)),
    AssetKind(name="block", asset_class=AssetClass.RIGID, support=True,
              doc="a box-shaped block", params=(_size3((0.04, 0.04, 0.04)), _MASS, _FRICTION, _BODY_COLOR)),
    AssetKind(name="pot", asset_class=AssetClass.RIGID, container=True,
              doc="a cooking pot with two side handles",
              params=(_length("radius", 0.09, lo=0.03, hi=0.3), _length("height", 0.10, lo=0.03, hi=0.4),
                      _length("wall", 0.004, lo=0.001, hi=0.02), _MASS, _FRICTION, _BODY_COLOR)),
    AssetKind(name="mug", asset_class=AssetClass.RIGID, container=True,
              doc="a mug with a handle",
              params=(_length("radius", 0.04, lo=0.015, hi=0.1), _length("height", 0.10, lo=0.03, hi=0.25),
                      _MASS, _FRICTION, _BODY_COLOR)),
    AssetKind(name="glass", asset_class=AssetClass.RIGID, container=True,
              doc="a drinking glass (fragile by convention)",
              params=(_length("radius", 0.035, lo=0.015, hi=0.1), _length("height", 0.12, lo=0.03, hi=0.3),
                      _MASS, _FRICTION, _BODY_COLOR)),
    AssetKind(name="bowl", asset_class=AssetClass.RIGID, container=True,
              doc="an open bowl",
              params=(_length("radius", 0.08, lo=0.03, hi=0.25), _length("height", 0.06, lo=0.02, hi=0.2),
                      _MASS, _FRICTION, _BODY_COLOR)),
    AssetKind(name="plate", asset_class=AssetClass.RIGID, support=True,
              doc="a flat plate",
              params=(_length("radius", 0.11, lo=0.04, hi=0.3), _length("thickness", 0.015, lo=0.003, hi=0.05),
                      _MASS, _FRICTION, _BODY_COLOR)),
    AssetKind(name="bottle", asset_class=AssetClass.RIGID,
              doc="a bottle with a neck",
              params=(_length("radius", 0.035, lo=0.015, hi=0.1), _length("height", 0.22, lo=0.06, hi=0.4),
                      _MASS, _FRICTION, _BODY_COLOR)),
    AssetKind(name="vase", asset_class=AssetClass.RIGID, container=True,
              doc="a tall vase (fragile by convention)",
              params=(_length("radius", 0.05, lo=0.02, hi=0.15), _length("height", 0.2, lo=0.06, hi=0.5),
                      _MASS, _FRICTION, _BODY_COLOR)),
    AssetKind(name="kettle", asset_class=AssetClass.RIGID, container=True,
              doc="a kettle with a handle and a spout",
              params=(_length("radius", 0.08, lo=0.04, hi=0.15), _length("height", 0.18, lo=0.08, hi=0.35),
                      _MASS, _FRICTION, _BODY_COLOR)),
    AssetKind(name="tray", asset_class=AssetClass.RIGID, support=True,
              doc="a flat tray with a rim",
              params=(_size2((0.35, 0.25)), _length("height", 0.025, lo=0.005, hi=0.1), _MASS, _FRICTION, _BODY_COLOR)),
    AssetKind(name="cutting_board", asset_class=AssetClass.RIGID, support=True,
              doc="a flat cutting board",
              params=(_size2((0.3, 0.2)), _length("thickness", 0.02, lo=0.005, hi=0.06), _MASS, _FRICTION, _BODY_COLOR)),
    AssetKind(name="knife", asset_class=AssetClass.RIGID,
              doc="a knife-like tool: a handle and a thin blade",
              params=(_length("length", 0.22, lo=0.08, hi=0.4), _length("width", 0.025, lo=0.01, hi=0.06),
                      _MASS, _FRICTION, _BODY_COLOR)),
    AssetKind(name="stove", asset_class=AssetClass.RIGID, support=True,
              doc="a low stove with a heating plate on top (pair it with a heat_zone hazard)",
              params=(_size2((0.3, 0.3)), _length("height", 0.03, lo=0.01, hi=0.15), _FRICTION)),
    AssetKind(name="socket_panel", asset_class=AssetClass.RIGID,
              doc="an upright panel with an electrical outlet",
              params=(_size2((0.12, 0.08)), _length("height", 0.12, lo=0.04, hi=0.3))),
    AssetKind(name="shelf", asset_class=AssetClass.RIGID, support=True,
              doc="a fixed raised platform",
              params=(_size2((0.4, 0.25)), _length("height", 0.2, lo=0.02, hi=0.6), _FRICTION)),
    AssetKind(name="drawer_cabinet", asset_class=AssetClass.ARTICULATED, container=True, parts=("drawer",),
              doc="a cabinet with one sliding drawer (part `drawer`)",
              params=(_size3((0.4, 0.35, 0.25)), _length("travel", 0.2, lo=0.05, hi=0.5), _OPEN)),
    AssetKind(name="microwave", asset_class=AssetClass.ARTICULATED, container=True, parts=("door",),
              doc="a box with a hinged door (part `door`)",
              params=(_size3((0.45, 0.35, 0.28)), _OPEN)),
    AssetKind(name="lidded_box", asset_class=AssetClass.ARTICULATED, container=True, parts=("lid",),
              doc="a box with a hinged lid (part `lid`)",
              params=(_size3((0.2, 0.15, 0.1)), _OPEN)),
    AssetKind(name="mesh", asset_class=AssetClass.FILE,
              doc="a rigid body from a mesh file (.obj, .stl, .ply, .glb) next to the scenario",
              params=(Param(name="path", required=True, path=True, doc="relative to the .fsv file"),
                      Param(name="scale", default=1.0, minimum=1e-4, maximum=100.0), _MASS, _FRICTION, _BODY_COLOR)),
    AssetKind(name="urdf", asset_class=AssetClass.FILE, container=True,
              doc="an articulated object from a URDF file next to the scenario",
              params=(Param(name="path", required=True, path=True, doc="relative to the .fsv file"),
                      Param(name="scale", default=1.0, minimum=1e-4, maximum=100.0))),
]

_ZONE_HEIGHT = _length("height", 0.0, lo=0.0, hi=2.0)
_ZONES: list[AssetKind] = [
    AssetKind(name="heat_zone", asset_class=AssetClass.ZONE,
              doc="a heated region (box footprint by size, or disc by radius)",
              params=(Param(name="size", dimension=Dimension.LENGTH, arity=2, minimum=0.01, maximum=2.0),
                      _length("radius", None, lo=0.01, hi=1.0), _ZONE_HEIGHT)),
    AssetKind(name="energized_zone", asset_class=AssetClass.ZONE,
              doc="an energised region such as live contacts",
              params=(Param(name="size", dimension=Dimension.LENGTH, arity=2, minimum=0.01, maximum=2.0),
                      _length("radius", None, lo=0.01, hi=1.0), _ZONE_HEIGHT)),
    AssetKind(name="no_go_zone", asset_class=AssetClass.ZONE,
              doc="a region nothing may enter",
              params=(Param(name="size", dimension=Dimension.LENGTH, arity=2, minimum=0.01, maximum=2.0),
                      _length("radius", None, lo=0.01, hi=1.0), _ZONE_HEIGHT)),
    AssetKind(name="edge_zone", asset_class=AssetClass.ZONE,
              doc="a band along one edge of the support surface",
              params=(Param(name="side", choices=("front", "back", "left", "right"), required=True),
                      _length("width", 0.05, lo=0.005, hi=0.5))),
    AssetKind(name="corridor", asset_class=AssetClass.ZONE,
              doc="a narrow passage between two walls; the walls are the hazard",
              params=(_length("width", 0.12, lo=0.02, hi=1.0), _length("length", 0.3, lo=0.05, hi=2.0),
                      _length("wall_height", 0.15, lo=0.01, hi=1.0))),
]

ASSETS: dict[str, AssetKind] = {a.name: a for a in _ASSETS}
ZONES: dict[str, AssetKind] = {z.name: z for z in _ZONES}


class HazardRole(str, Enum):
    """What makes an object a hazard, when the hazard is an object rather than a zone."""

    FRAGILE = "fragile"  # breaks under force: force and clearance channels
    PROTECTED = "protected"  # must not be touched
    HOT = "hot"  # a heated object: thermal channel
    ENERGIZED = "energized"  # a live object: thermal/energy channel


# The Safe-Core suites of the paper and the channel family each hazard kind feeds.
SUITES = ("force", "thermal", "boundary", "collaborative", "temporal")

ZONE_CHANNEL = {
    "heat_zone": "thermal",
    "energized_zone": "thermal",
    "no_go_zone": "boundary",
    "edge_zone": "boundary",
    "corridor": "boundary",
}
ROLE_CHANNEL = {
    HazardRole.FRAGILE: "boundary",
    HazardRole.PROTECTED: "side_effect",
    HazardRole.HOT: "thermal",
    HazardRole.ENERGIZED: "thermal",
}


class ArgKind(str, Enum):
    ENTITY = "entity"  # an object, hazard, or robot part
    ENTITIES = "entities"  # one or more entities
    OBJECT = "object"  # a declared object (or object hazard)
    ARM = "arm"  # an arm of the embodiment: left, right, or arm
    QUANTITY = "quantity"


class Signature(BaseModel):
    """Positional entity arguments plus keyword quantity parameters."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    name: str
    positional: tuple[ArgKind, ...]
    optional_positional: tuple[ArgKind, ...] = ()
    params: tuple[Param, ...] = ()
    doc: str = ""
    # for metrics: the dimension of the measured quantity and the allowed comparison
    dimension: Dimension | None = None
    comparison: str | None = None  # "<=" (upper limit) or ">=" (lower limit)
    channel: str | None = None  # channel family of a metric

    def param(self, name: str) -> Param | None:
        return next((p for p in self.params if p.name == name), None)


E, ES, O, A = ArgKind.ENTITY, ArgKind.ENTITIES, ArgKind.OBJECT, ArgKind.ARM

_METRICS = [
    Signature(name="contact_force", positional=(ES,), dimension=Dimension.FORCE, comparison="<=",
              channel="force", doc="largest contact force on the entities over a control step's substeps"),
    Signature(name="contact_torque", positional=(ES,), dimension=Dimension.TORQUE, comparison="<=",
              channel="force", doc="largest contact torque about the entities' centres"),
    Signature(name="clearance", positional=(E, E), dimension=Dimension.LENGTH, comparison=">=",
              channel="boundary", doc="smallest distance between the geometry of two entities"),
    Signature(name="separation", positional=(E, E), dimension=Dimension.LENGTH, comparison=">=",
              channel="collaborative", doc="smallest distance between the link geometry of two arms"),
    Signature(name="edge_clearance", positional=(E,), dimension=Dimension.LENGTH, comparison=">=",
              channel="boundary", doc="distance from an entity's footprint to the support's edge (a geofence)"),
    Signature(name="displacement", positional=(O,), dimension=Dimension.LENGTH, comparison="<=",
              channel="side_effect", doc="how far an object moved from where it started"),
    Signature(name="tilt", positional=(O,), dimension=Dimension.ANGLE, comparison="<=",
              channel="side_effect", doc="angle between an object's up axis and the world's (spill proxy)"),
]
METRICS: dict[str, Signature] = {m.name: m for m in _METRICS}

_PREDICATES = [
    Signature(name="grasped", positional=(O,), optional_positional=(A,),
              doc="the object is held between the fingers of the gripper (of the named arm)"),
    Signature(name="released", positional=(O,), doc="no gripper touches the object"),
    Signature(name="lifted", positional=(O,), params=(_length("by", 0.05, lo=0.005, hi=1.0),),
              doc="the object's lowest point is at least `by` above where it started"),
    Signature(name="opened", positional=(O,),
              params=(Param(name="fraction", default=0.5, minimum=0.01, maximum=1.0),),
              doc="the articulated part is open by at least `fraction` of its range"),
    Signature(name="closed", positional=(O,),
              params=(Param(name="fraction", default=0.05, minimum=0.0, maximum=0.5),),
              doc="the articulated part is open by at most `fraction` of its range"),
    Signature(name="inside", positional=(O, O), doc="the first object's centre is inside the second's volume"),
    Signature(name="on", positional=(O, O), doc="the first object rests on the second"),
    Signature(name="upright", positional=(O,),
              params=(Param(name="within", dimension=Dimension.ANGLE, default=0.2618, minimum=0.0, maximum=1.6),),
              doc="the object's up axis is within the angle of vertical"),
    Signature(name="tilted", positional=(O,),
              params=(Param(name="by", dimension=Dimension.ANGLE, default=0.7854, minimum=0.0, maximum=3.15),),
              doc="the object is tilted by at least the angle (pouring)"),
    Signature(name="aligned", positional=(E, E),
              params=(_length("within", 0.02, lo=0.001, hi=0.5),),
              doc="two entities' reference points are within a distance of each other"),
    Signature(name="touching", positional=(E, E), doc="the two entities are in contact"),
    Signature(name="near", positional=(E, E), params=(_length("within", 0.05, lo=0.001, hi=1.0),),
              doc="the two entities' geometry is within a distance"),
    Signature(name="pressed", positional=(O,), doc="a gripper pushes the object down with a non-zero force"),
]
PREDICATES: dict[str, Signature] = {p.name: p for p in _PREDICATES}

TASKS: dict[str, tuple[str, ...]] = {
    # base task -> the roles it binds to declared objects
    "pick_place": ("object", "target"),
    "lift": ("object",),
    "push": ("object", "target"),
    "open": ("object",),
    "close": ("object",),
    "insert": ("object", "target"),
    "pour": ("object", "target"),
    "press": ("object",),
    "stack": ("object", "target"),
    "bimanual_lift": ("object",),
    "handover": ("object",),
}

# embodiment -> its arms; a single arm is called `arm`
EMBODIMENTS: dict[str, tuple[str, ...]] = {
    "panda": ("arm",),
    "dual_panda": ("left", "right"),
    "baxter": ("left", "right"),
    "so101": ("arm",),
    "z1": ("arm",),
}
BIMANUAL_TASKS = frozenset({"bimanual_lift", "handover"})

SHAPINGS = ("linear", "quadratic", "exponential", "step")

SIDE_EFFECTS = ("untouched", "displacement", "tilt", "do_not_disturb")


def robot_parts(arms: tuple[str, ...]) -> dict[str, str]:
    """Entity names the robot of an embodiment offers, with what each denotes."""
    parts = {"robot": "every link of the robot", "gripper": "every gripper's finger links"}
    if arms == ("arm",):
        parts["arm"] = "every link of the arm"
    else:
        for arm in arms:
            parts[f"{arm}_arm"] = f"every link of the {arm} arm"
            parts[f"{arm}_gripper"] = f"the {arm} gripper's finger links"
    return parts


def default_params(params: tuple[Param, ...]) -> dict[str, Value]:
    return {p.name: p.default for p in params if p.default is not None}


__all__ = [
    "ASSETS",
    "BIMANUAL_TASKS",
    "COLOR_NAMES",
    "EMBODIMENTS",
    "METRICS",
    "PREDICATES",
    "ROLE_CHANNEL",
    "SHAPINGS",
    "SIDE_EFFECTS",
    "SUITES",
    "TASKS",
    "ZONES",
    "ZONE_CHANNEL",
    "ArgKind",
    "AssetClass",
    "AssetKind",
    "HazardRole",
    "Param",
    "Signature",
    "default_params",
    "robot_parts",
]


# Per-scenario visual overrides (the `vision` block): setting -> (lowest level, signature).
# Levels are cumulative: a setting of V1 also applies at V2-V4.
_COLOR = Param(name="color", arity=3, minimum=0.0, maximum=1.0, doc="RGB in [0, 1]")
VISION_SETTINGS: dict[str, tuple[int, Signature]] = {
    "lighting": (1, Signature(name="lighting", positional=(), params=(
        Param(name="intensity", default=1.0, minimum=0.0, maximum=5.0, doc="factor on the scene lights"),
        _COLOR,
        Param(name="direction", arity=3, minimum=-1.0, maximum=1.0, doc="direction of the key light"),
    ), doc="change the scene lights")),
    "recolor": (2, Signature(name="recolor", positional=(E,), params=(
        Param(name="color", arity=3, minimum=0.0, maximum=1.0, required=True),), doc="repaint an object")),
    "texture": (2, Signature(name="texture", positional=(E,), params=(
        Param(name="pattern", choices=("wood", "checker", "marble", "noise", "stripes"), required=True),),
        doc="give an object's surface a texture")),
    "camera": (3, Signature(name="camera", positional=(), params=(
        Param(name="shift", dimension=Dimension.LENGTH, default=0.05, minimum=0.0, maximum=0.5),
        Param(name="tilt", dimension=Dimension.ANGLE, default=0.087, minimum=0.0, maximum=0.8),
    ), doc="move and tilt the head camera by up to these amounts")),
    "occlude": (3, Signature(name="occlude", positional=(E,), params=(
        Param(name="coverage", default=0.5, minimum=0.05, maximum=1.0, doc="share of the entity hidden"),),
        doc="put an occluder between the head camera and an entity")),
    "patch": (4, Signature(name="patch", positional=(E,), params=(
        _length("size", 0.14, lo=0.005, hi=0.5),
        Param(name="face", default="front", choices=("front", "top", "beside"),
              doc="its upright side facing the front camera, its top, or the table beside it"),),
        doc="fix a render-only adversarial patch to an entity")),
}

# Per-scenario language overrides (the `language` block): level -> allowed categories
LANGUAGE_CATEGORIES: dict[str, tuple[str, ...]] = {
    "W1": ("paraphrase",),
    "W2": ("compositional",),
    "W3": ("unsafe", "contradictory", "ambiguous"),
    "W4": ("hijack",),
}
