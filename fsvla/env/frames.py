"""Which pictures an environment renders, and when.

Rendering is the real cost of an rgb episode (two 320×240 cameras on lavapipe take
tens of milliseconds a step), and a policy that returns a chunk of actions looks at one
observation in many. An environment made with ``lazy_images=True`` (the runner makes
them so) returns ``obs["images"]`` as a :class:`LazyImages`: a dict whose pictures are
rendered the first time one of them is read, for the step that produced the
observation, and kept. A step whose pictures nobody reads renders nothing. Physics never
reads a picture, so an episode's states are the same whichever steps are rendered.

A picture can only be rendered while the scene is still at its step: reading the images
of such an observation after the environment has stepped again (or reset) raises
:class:`StaleFrameError`. So the default (``lazy_images=False``) renders every step and
returns plain dicts, as gymnasium's contract has it (an observation stays whole however
long it is kept); the runner renders an observation in full before a policy sees it
(:meth:`LazyImages.fill`), so a policy may keep the observations it is given.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

Images = dict[str, NDArray[np.uint8]]


class StaleFrameError(RuntimeError):
    """The images of an observation read after the environment moved past its step."""


class LazyImages(dict):
    """Camera name -> ``H × W × 3`` uint8 picture, rendered at the first read.

    The keys (the cameras) are there from the start; reading a value (``[]``, ``get``,
    ``values``, ``items``, ``==``, copying, pickling) renders every camera of the step
    once, through ``render``, which raises :class:`StaleFrameError` when the step has
    passed. It is a ``dict`` so that gymnasium's spaces accept it; it pickles and
    deep-copies as a plain dict of its pictures."""

    def __init__(self, cameras: Iterable[str], render: Callable[[], Mapping[str, Any]]) -> None:
        super().__init__(dict.fromkeys(cameras))
        self._render: Callable[[], Mapping[str, Any]] | None = render

    @property
    def rendered(self) -> bool:
        """Whether the pictures have been rendered."""
        return self._render is None

    def fill(self) -> None:
        """Render the pictures now (nothing when they are): the observation is then whole."""
        self._fill()

    def _fill(self) -> None:
        if self._render is not None:
            pictures = self._render()
            dict.update(self, {name: pictures[name] for name in dict.keys(self)})
            self._render = None

    def __getitem__(self, key: str) -> NDArray[np.uint8]:
        self._fill()
        return dict.__getitem__(self, key)

    def __iter__(self):  # keys only; defining it makes dict(x) and {**x} read through items
        return dict.__iter__(self)

    def get(self, key: str, default: Any = None) -> Any:
        self._fill()
        return dict.get(self, key, default)

    def values(self):  # type: ignore[override]
        self._fill()
        return dict.values(self)

    def items(self):  # type: ignore[override]
        self._fill()
        return dict.items(self)

    def copy(self) -> Images:  # type: ignore[override]
        self._fill()
        return dict(dict.items(self))

    def pop(self, key: str, *default: Any) -> Any:  # type: ignore[override]
        self._fill()
        return dict.pop(self, key, *default)

    def popitem(self) -> tuple[str, Any]:
        self._fill()
        return dict.popitem(self)

    def setdefault(self, key: str, default: Any = None) -> Any:  # type: ignore[override]
        self._fill()
        return dict.setdefault(self, key, default)

    def __eq__(self, other: object) -> bool:
        self._fill()
        return dict.__eq__(self, other)

    def __ne__(self, other: object) -> bool:
        return not self == other

    __hash__ = None  # type: ignore[assignment]

    def __reduce__(self) -> tuple[Any, ...]:
        return (dict, (self.copy(),))

    def __repr__(self) -> str:
        if self._render is not None:
            return f"LazyImages({list(dict.keys(self))}, not rendered yet)"
        return f"LazyImages({dict.__repr__(self)})"


__all__ = ["Images", "LazyImages", "StaleFrameError"]
