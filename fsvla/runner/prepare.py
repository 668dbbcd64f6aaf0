"""From ``fsvla run`` options to a checked run: scenarios loaded, configuration, plan.

Everything here happens before anything is written: a bad option value raises
:class:`RunInputError`, whose ``option`` names the option and whose message says what is
wrong with it (the CLI prints it and exits 2).
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from fsvla.run.config import RunConfig, config_differences
from fsvla.run.plan import EpisodeSpec, PlannedScenario, plan_episodes

#: Which option sets each RunConfig field (for error messages).
OPTIONS: dict[str, str] = {
    "policy": "--policy", "scenarios": "--scenarios", "levels": "--levels",
    "languages": "--language", "visions": "--vision", "episodes": "--episodes",
    "seeds": "--seeds", "warmup": "--warmup", "control_mode": "--control-mode",
    "obs_mode": "--obs-mode", "embodiment": "--embodiment", "sasr_lambda": "--sasr-lambda",
    "cameras": "--cameras", "resolution": "--resolution", "shader": "--shader", "patch": "--patch",
    "terminate_on_violation": "--terminate-on-violation", "policy_timeout_s": "--policy-timeout",
    "policy_profile": "--policy-profile", "replan_steps": "--replan-steps", "sweep": "--sweep",
}


class RunInputError(ValueError):
    """A ``fsvla run`` input that cannot be used; ``option`` names the option."""

    def __init__(self, option: str, message: str) -> None:
        self.option = option
        super().__init__(message if message.startswith(option) else f"{option}: {message}")


@dataclass(frozen=True)
class PreparedRun:
    """A run ready to execute: its configuration, scenarios and every planned episode."""

    config: RunConfig
    scenarios: tuple[PlannedScenario, ...]
    plan: tuple[EpisodeSpec, ...]


def scenario_refs(items: Sequence[str]) -> list[str]:
    """The scenarios ``--scenarios`` names (comma-separated, repeatable), resolved by
    :func:`fsvla.selectors.resolve_scenarios`: ``.fsv`` files, folders (``_base/`` skipped),
    built-in names, and ``subset:``/``suite:``/``embodiment:`` selectors."""
    from fsvla.selectors import ScenarioSelectionError, resolve_scenarios

    try:
        return resolve_scenarios(items)
    except ScenarioSelectionError as err:
        raise RunInputError("--scenarios", str(err)) from None


def plan_scenarios(items: Sequence[str]) -> list[PlannedScenario]:
    """Load and check every scenario ``--scenarios`` names."""
    from fsvla.library import ScenarioLoadError, load_scenario

    planned = []
    for ref in scenario_refs(items):
        try:
            planned.append(PlannedScenario.of(load_scenario(ref), ref=ref))
        except ScenarioLoadError as err:
            raise RunInputError("--scenarios", str(err)) from None
    return planned


def make_config(**fields: Any) -> RunConfig:
    """A :class:`RunConfig`, with a validation error reported against its option."""
    try:
        config = RunConfig(**fields)
    except ValidationError as err:
        first = err.errors()[0]
        field = str(first["loc"][0]) if first["loc"] else ""
        raise RunInputError(OPTIONS.get(field, field or "options"), first["msg"]) from None
    if config.obs_mode == "state" and config.visions != ("V0",):
        raise RunInputError("--vision", f"{', '.join(v for v in config.visions if v != 'V0')} "
                            "change only the pictures a policy sees; they need --obs-mode rgb")
    if config.patch is not None and "V4" not in config.visions:
        raise RunInputError("--patch", "--patch gives V4's patch its pixels, and the run has no "
                            f"V4 (--vision {','.join(config.visions)})")
    if config.policy_profile is not None:
        _check_profile(config)
    if config.embodiment is not None:
        from fsvla.embodiments import load_embodiment

        try:
            load_embodiment(config.embodiment)
        except (KeyError, ValueError, OSError) as err:
            raise RunInputError("--embodiment", str(err.args[0] if err.args else err)) from None
    return config


def profile_defaults(fields: dict[str, Any], given: Collection[str]) -> dict[str, Any]:
    """``fields`` (RunConfig fields) with what their ``policy_profile`` decides unless an
    option sets it (``given``: the fields set by options): the control mode its actions
    are in, its replan steps, rgb observations when it sends images. A stored run's value
    stays, unless the profile is given anew."""
    spec = fields.get("policy_profile")
    if not spec:
        return fields
    profile = _load_profile(spec)
    decided = {"control_mode": profile.control_mode, "replan_steps": profile.replan_steps,
               "obs_mode": "rgb" if profile.sends_images else None}
    fields = dict(fields)
    for name, value in decided.items():
        if value is not None and name not in given and (
                fields.get(name) is None or "policy_profile" in given):
            fields[name] = value
    return fields


def _check_profile(config: RunConfig) -> None:
    """A profile must speak to a policy server, in its own control mode, with the
    pictures it sends."""
    profile = _load_profile(config.policy_profile or "")
    if not config.policy.startswith(("ws://", "wss://")):
        raise RunInputError("--policy-profile", f"--policy-profile maps the keys of a policy "
                            f"server (--policy ws://host:port); --policy {config.policy} is none")
    if profile.control_mode is not None and config.control_mode != profile.control_mode:
        raise RunInputError("--control-mode", f"profile {profile.name} decodes its server's "
                            f"actions as {profile.control_mode}, not {config.control_mode}; "
                            "leave --control-mode out (the profile sets it)")
    if profile.sends_images and config.obs_mode != "rgb":
        raise RunInputError("--obs-mode", f"profile {profile.name} sends camera images; it "
                            "needs --obs-mode rgb (the default with this profile)")


def _load_profile(spec: str):  # -> Profile
    from fsvla.policies.profile import ProfileError, load_profile

    try:
        return load_profile(spec)
    except ProfileError as err:
        raise RunInputError("--policy-profile", str(err)) from None


def prepare_run(config: RunConfig) -> PreparedRun:
    """Load the configuration's scenarios and plan its episodes."""
    scenarios = plan_scenarios(config.scenarios)
    try:
        plan = plan_episodes(config, scenarios)
    except ValueError as err:
        raise RunInputError("--scenarios", str(err)) from None
    if config.cameras is not None:
        check_cameras(config.cameras, config.embodiment, scenarios)
    return PreparedRun(config=config, scenarios=tuple(scenarios), plan=tuple(plan))


def check_cameras(cameras: Sequence[str], embodiment: str | None,
                  scenarios: Sequence[PlannedScenario]) -> None:
    """Every camera ``--cameras`` names must be one of each scenario's embodiment
    (``embodiment`` when it overrides theirs)."""
    from fsvla.embodiments import load_embodiment
    from fsvla.sim.cameras import check_camera_names

    for name in dict.fromkeys(embodiment or s.embodiment for s in scenarios):
        known = [c.name for c in load_embodiment(name).cameras]
        try:
            check_camera_names(cameras, known)
        except ValueError as err:
            raise RunInputError("--cameras", f"embodiment {name}: {err}") from None


def check_run_folder(out: Path, config: RunConfig, *, extend: bool = False) -> bool:
    """Whether ``out`` holds a run to resume; raises :class:`RunInputError` when it holds
    one this configuration cannot resume (or extend), or something else altogether."""
    from fsvla.results import ResultStore, RunConfigMismatch
    from fsvla.results.schema import SCHEMA_VERSION
    from fsvla.results.store import older_schema

    if out.exists() and not out.is_dir():
        raise RunInputError("--out", f"{out} is a file, not a run folder")
    try:
        if not ResultStore.exists(out):
            return False
        with ResultStore.open(out, readonly=True) as store:
            stored = store.config
            version = store.schema_version
    except ValueError as err:
        raise RunInputError("--out", str(err)) from None
    if version != SCHEMA_VERSION:
        raise RunInputError("--out", older_schema(out, version))
    differences = config_differences(stored, config)
    fixed = [d for d in differences if not d.extendable]
    if fixed or (differences and not extend):
        mismatch = RunConfigMismatch(out, fixed if extend else differences, extend)
        raise RunInputError("--out", str(mismatch))
    return True


__all__ = ["OPTIONS", "PreparedRun", "RunInputError", "check_run_folder", "make_config",
           "plan_scenarios", "prepare_run", "profile_defaults", "scenario_refs"]
