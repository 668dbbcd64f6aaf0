"""The ``language`` (W1–W4) and ``vision`` (V1–V4) blocks: a scenario's own perturbations."""

from __future__ import annotations

from .. import ast, models
from ..catalog import LANGUAGE_CATEGORIES, VISION_SETTINGS
from ..diagnostics import did_you_mean
from .binding import bind_params
from .scope import Part, source_ref


class LanguageChecker(Part):
    def language(self) -> dict:
        out: dict = {}
        for level_name, entries in self.scope.merged.language.items():
            if level_name not in LANGUAGE_CATEGORIES:
                self.sink.error("FSV504", f"unknown language level `{level_name}`", entries[0].level.span,
                                "not W1-W4", help="W0 is the canonical `instruction`; override W1 "
                                "(paraphrase), W2 (compositional), W3 (unsafe, contradictory, ambiguous) "
                                "or W4 (hijack suffix)")
                continue
            variants = []
            for entry in entries:
                variants.extend(self._entry(level_name, entry))
            out[level_name] = tuple(variants)
        return out

    def _entry(self, level_name: str, entry: ast.LanguageEntry) -> list[models.LanguageVariant]:
        allowed = LANGUAGE_CATEGORIES[level_name]
        category = entry.category.value if entry.category else None
        if category is None and len(allowed) > 1:
            self.sink.error("FSV504", f"{level_name} needs a category", entry.level.span,
                            "which kind of request?",
                            help=f"write `{level_name} {allowed[0]}: \"...\"`; categories: "
                                 + ", ".join(allowed))
            return []
        if category is not None and category not in allowed:
            self.sink.error("FSV504", f"`{category}` is not a category of {level_name}",
                            entry.category.span, "wrong category",
                            help=did_you_mean(category, allowed, "categories"))
            return []
        variants = []
        for text in entry.texts:
            if not text.value.strip():
                self.sink.error("FSV207", "an empty instruction", text.span, "empty string")
                continue
            variants.append(models.LanguageVariant(text=text.value, category=category or allowed[0],
                                                   source=source_ref(text.span)))
        return variants


class VisionChecker(Part):
    def vision(self) -> dict:
        out: dict = {}
        for level_name, entry in self.scope.merged.vision.items():
            if level_name not in ("V1", "V2", "V3", "V4"):
                self.sink.error("FSV505", f"unknown vision level `{level_name}`", entry.level.span,
                                "not V1-V4", help="V0 is the canonical view; override V1 (lighting), "
                                "V2 (appearance), V3 (viewpoint, occlusion) or V4 (adversarial patch)")
                continue
            level = int(level_name[1])
            settings = [self._setting(call, level) for call in entry.settings]
            out[level_name] = tuple(s for s in settings if s is not None)
        return out

    def _setting(self, call: ast.Call, level: int) -> models.VisionSetting | None:
        name = call.name.value
        if name not in VISION_SETTINGS:
            self.sink.error("FSV505", f"unknown vision setting `{name}`", call.name.span, "not a setting",
                            help=did_you_mean(name, VISION_SETTINGS, "settings"))
            return None
        lowest, signature = VISION_SETTINGS[name]
        if level < lowest:
            self.sink.error("FSV505", f"`{name}` belongs to V{lowest} and above", call.name.span,
                            f"not a V{level} perturbation",
                            help=f"move it under `V{lowest}:`; levels are cumulative, so it applies from there on")
            return None
        params: dict = {}
        positional = call.positional
        if len(positional) != len(signature.positional):
            self.sink.error("FSV305", f"`{name}` takes {len(signature.positional)} name(s)", call.span,
                            f"{len(positional)} given", help=signature.doc)
            return None
        if positional:
            target = self.scope.arg_entity(positional[0], signature)
            if target is None:
                return None
            params["target"] = target
        params.update(bind_params(self.scope, ast.Call(call.name, call.keywords, call.span), signature.params,
                                  name, positional_ok=False))
        return models.VisionSetting(name=name, params=params, source=source_ref(call.span))
