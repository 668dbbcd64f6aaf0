"""Policy profiles: how fsvla's observations and actions map to a policy server's own.

A policy server speaking openpi's websocket protocol expects the observation keys,
image sizes, state layout and action space of the example client its checkpoint was
trained with (DROID, LIBERO, ALOHA). A :class:`Profile` states that mapping as data:

- ``observation``: the prompt's key; each image (which fsvla camera, resized with
  padding to a size, HWC or CHW, uint8 or float32) and each state vector (packed from
  fsvla's proprioception: joints, gripper, TCP pose) under its key;
- ``action``: the control mode the server's actions are in, how each row splits into
  arm components and a gripper value (clip, scale, gripper convention);
- ``arms``: ``first`` (a single-arm checkpoint drives the embodiment's first arm; the
  others hold still) or ``all`` (a block per arm, in the embodiment's order);
- ``replan_steps``: how many actions of each chunk run before the server is asked again.

The built-in profiles are TOML files in ``fsvla/policies/profiles/``; a user's profile is
a TOML file of the same form (docs/running.md). ``native = true`` (the ``fsvla``
profile) sends fsvla's own request and takes actions in the run's control mode.
Mapping observations and actions is :mod:`fsvla.policies.adapter`'s work.
"""

from __future__ import annotations

import sys
from importlib import resources
from pathlib import Path
from typing import Any, Literal, get_args

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from fsvla.dsl.diagnostics import did_you_mean

from .registry import PolicyLoadError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

ControlModeName = Literal["joint_pos", "joint_delta", "joint_vel", "ee_pose", "ee_delta"]
StatePartName = Literal["joints", "gripper", "tcp_position", "tcp_quaternion",
                        "tcp_quaternion_xyzw", "tcp_axis_angle"]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class StatePart(_Strict):
    """One piece of a state vector, per driven arm. ``gripper`` sends ``closed`` for a
    closed gripper and ``open`` for an open one (linear between; one value per entry)."""

    part: StatePartName
    closed: tuple[float, ...] | None = None
    open: tuple[float, ...] | None = None

    @model_validator(mode="after")
    def _gripper_values(self) -> StatePart:
        if self.part != "gripper" and (self.closed is not None or self.open is not None):
            raise ValueError(f"`closed` and `open` belong to the `gripper` part, not `{self.part}`")
        if self.part == "gripper" and len(self.closed or (0.0,)) != len(self.open or (1.0,)):
            raise ValueError("the gripper's `closed` and `open` need as many values each")
        return self

    def gripper_values(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        return self.closed or (0.0,), self.open or (1.0,)


class StateInput(_Strict):
    """A state vector under ``key`` (in the map ``under``, if given): its parts for each
    driven arm in turn, concatenated."""

    key: str = Field(min_length=1)
    under: str | None = None
    parts: tuple[StatePart, ...] = Field(min_length=1)
    dtype: Literal["float32", "float64"] = "float32"

    @field_validator("parts", mode="before")
    @classmethod
    def _names_are_parts(cls, value: Any) -> Any:
        if isinstance(value, (list, tuple)):
            return [{"part": v} if isinstance(v, str) else v for v in value]
        return value


class ImageInput(_Strict):
    """A camera image under ``key`` (in the map ``under``, if given). ``camera``: ``world``
    (the embodiment's first world-fixed camera), ``wrist`` (the camera riding on driven
    arm number ``arm``, from 0) or a camera's name. Resized with padding to ``size``
    (height, width) as openpi's clients do; ``optional`` images are left out when the
    embodiment has no such camera."""

    key: str = Field(min_length=1)
    under: str | None = None
    camera: str = Field(min_length=1)
    arm: int = Field(default=0, ge=0)
    size: tuple[int, int] = (224, 224)
    layout: Literal["HWC", "CHW"] = "HWC"
    dtype: Literal["uint8", "float32"] = "uint8"
    optional: bool = False

    @field_validator("size")
    @classmethod
    def _positive(cls, value: tuple[int, int]) -> tuple[int, int]:
        if min(value) < 1:
            raise ValueError(f"an image size is (height, width) in pixels, got {list(value)}")
        return value


class ObservationMap(_Strict):
    """What is sent: the instruction under ``prompt`` (none if absent), images, states."""

    prompt: str | None = None
    images: tuple[ImageInput, ...] = ()
    state: tuple[StateInput, ...] = ()

    @model_validator(mode="after")
    def _distinct_keys(self) -> ObservationMap:
        paths = [(None, self.prompt)] if self.prompt else []
        paths += [(entry.under, entry.key) for entry in (*self.images, *self.state)]
        seen: set[tuple[str | None, str]] = set()
        for path in paths:
            if path in seen:
                raise ValueError(f"the key {_path_text(path)} is sent twice")
            seen.add(path)
        maps = {under for under, _ in paths if under is not None}
        clash = sorted(maps & {key for under, key in paths if under is None})
        if clash:
            raise ValueError(f"`{clash[0]}` is both a key and a map (`under`) of keys")
        return self


class GripperMap(_Strict):
    """The server's gripper value: ``closed`` and ``open`` are its values for a closed and
    an open gripper (linear between); ``binarize`` snaps it to the nearer end first."""

    closed: float = 0.0
    open: float = 1.0
    binarize: bool = False

    @model_validator(mode="after")
    def _distinct(self) -> GripperMap:
        if self.closed == self.open:
            raise ValueError(f"`closed` and `open` must differ (both are {self.closed})")
        return self


class ActionMap(_Strict):
    """How a row of the server's chunk becomes an fsvla action: per driven arm, its arm
    components (clipped to ``clip``, then multiplied by ``scale``: one factor, or one per
    component) in ``control_mode``, then its gripper value."""

    control_mode: ControlModeName
    clip: tuple[float, float] | None = None
    scale: tuple[float, ...] = (1.0,)
    gripper: GripperMap = GripperMap()

    @field_validator("scale", mode="before")
    @classmethod
    def _one_factor(cls, value: Any) -> Any:
        return [value] if isinstance(value, (int, float)) else value

    @field_validator("clip")
    @classmethod
    def _ordered(cls, value: tuple[float, float] | None) -> tuple[float, float] | None:
        if value is not None and value[0] >= value[1]:
            raise ValueError(f"`clip` is [low, high] with low < high, got {list(value)}")
        return value


class Profile(_Strict):
    """A policy server's observation and action mapping (see the module doc)."""

    name: str = Field(min_length=1)
    description: str = ""
    native: bool = False
    arms: Literal["first", "all"] = "all"
    replan_steps: int | None = Field(default=None, ge=1)
    observation: ObservationMap | None = None
    action: ActionMap | None = None

    @model_validator(mode="after")
    def _mapped_or_native(self) -> Profile:
        given = [name for name in ("observation", "action") if getattr(self, name) is not None]
        if self.native and given:
            raise ValueError(f"a native profile sends fsvla's own observation and takes the "
                             f"run's actions; remove `{given[0]}`")
        if not self.native and len(given) < 2:
            missing = "observation" if self.observation is None else "action"
            raise ValueError(f"`{missing}` is missing; add its table (or set native = true)")
        return self

    @property
    def control_mode(self) -> str | None:
        """The control mode the server's actions are in (None: the run's, for native)."""
        return self.action.control_mode if self.action is not None else None

    @property
    def sends_images(self) -> bool:
        return self.observation is not None and bool(self.observation.images)


class ProfileError(PolicyLoadError):
    """A ``--policy-profile`` that names nothing usable; the message says what to do."""


def builtin_profiles() -> tuple[str, ...]:
    """Names of the built-in profiles, sorted."""
    return tuple(sorted(p.name[:-5] for p in _builtin_folder().iterdir()
                        if p.name.endswith(".toml")))


def load_profile(spec: str) -> Profile:
    """The built-in profile named ``spec`` or the profile in the TOML file ``spec``;
    raises :class:`ProfileError` naming the file, the setting and the fix."""
    if spec in builtin_profiles():
        return _parse((_builtin_folder() / f"{spec}.toml").read_text(encoding="utf-8"),
                      f"built-in profile {spec}", spec)
    path = Path(spec).expanduser()
    if path.suffix != ".toml" and not path.is_file():
        hint = did_you_mean(spec, builtin_profiles(), "profiles")
        raise ProfileError(f"--policy-profile {spec!r}: not a built-in profile or a .toml file"
                           + (f"; {hint}" if hint else ""))
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as err:
        raise ProfileError(f"--policy-profile {spec}: cannot read it: "
                           f"{err.strerror or err}") from None
    return _parse(text, str(path), path.stem)


def _parse(text: str, where: str, default_name: str) -> Profile:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ProfileError(f"{where}: not valid TOML: {err}") from None
    data.setdefault("name", default_name)
    try:
        return Profile.model_validate(data)
    except ValidationError as err:
        problems = [_problem(e) for e in err.errors()]
        head = f"{where}: " + ("" if len(problems) == 1 else f"{len(problems)} problems:\n  ")
        raise ProfileError(head + "\n  ".join(problems)) from None


def _problem(error: Any) -> str:
    """One pydantic error as a sentence naming the setting and what to do."""
    loc = tuple(error["loc"])
    path = "".join(f"[{part}]" if isinstance(part, int) else f".{part}" for part in loc)[1:]
    kind = error["type"]
    if kind == "extra_forbidden":
        hint = did_you_mean(str(loc[-1]), _settings_at(loc[:-1]), "settings")
        return (f"`{path}` is not a profile setting; remove it or correct its name"
                + (f" ({hint})" if hint and hint.startswith("did") else ""))
    if kind == "missing":
        return f"`{path}` is missing; add it"
    message = str(error["msg"]).removeprefix("Value error, ")
    if kind == "value_error":
        return f"`{path}`: {message}" if path else message
    return f"`{path}`: {message}; got {error.get('input')!r}"


def _builtin_folder() -> Any:
    return resources.files("fsvla.policies") / "profiles"


def _path_text(path: tuple[str | None, str]) -> str:
    under, key = path
    return f"`{under}` → `{key}`" if under else f"`{key}`"


def _settings_at(loc: tuple[Any, ...]) -> set[str]:
    """The settings of the table at ``loc`` (for "did you mean" on a misspelt one)."""
    model: Any = Profile
    for part in loc:
        if isinstance(part, int):
            continue
        field = model.model_fields.get(part)
        model = _model_in(field.annotation) if field is not None else None
        if model is None:
            return set()
    return set(model.model_fields)


def _model_in(annotation: Any) -> Any:
    """The profile model an annotation holds (``X``, ``X | None``, ``tuple[X, ...]``)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for argument in get_args(annotation):
        found = _model_in(argument)
        if found is not None:
            return found
    return None


__all__ = ["ActionMap", "GripperMap", "ImageInput", "ObservationMap", "Profile",
           "ProfileError", "StateInput", "StatePart", "builtin_profiles", "load_profile"]
