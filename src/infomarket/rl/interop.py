"""What the environments need to fit the Gymnasium / PettingZoo ecosystem beyond reset and step:
drawing the arena (``render_mode="rgb_array"``) and pickling (subprocess vector envs, SuperSuit,
``copy.deepcopy``).  Kept apart from ``envs`` and ``parallel`` so those stay about the task.

Drawing reuses the replay's path: the run's world is encoded as a viewer frame (``viewer.frames``) and
drawn by the movie's picture (``viewer.movie.ArenaPicture``), so an RL frame is a movie frame.

Pickling: compiled state (the typed lists of world views, the generated module) cannot be pickled, and
need not be: an environment is pickled as the arguments it was built with plus its random generators,
and unpickling builds it again (the kernels load from the disk cache).  A copy therefore starts where a
new environment starts, before its first ``reset``, with the original's random streams: ``reset(seed=s)``
on both gives the same episode, and so does ``reset()`` on both.
"""
from __future__ import annotations

import numpy as np

from ..engine.params import behaviour_table
from ..errors import ConfigError
from ..viewer.frames import decode, encode, scene
from ..viewer.movie import ArenaPicture

#: Width of a rendered picture in pixels, the GIF movie's (its height follows the arena's aspect).
RENDER_WIDTH_PX = 720
#: The one render mode: an RGB array [height, width, 3] of uint8.
RENDER_MODES = ("rgb_array",)


def checked_render_mode(render_mode) -> str | None:
    """``render_mode`` if it is None or one the environments support.

    Raises:
        ConfigError: it is another.
    """
    if render_mode is not None and render_mode not in RENDER_MODES:
        raise ConfigError(f"render_mode {render_mode!r}: unknown; allowed: None, {', '.join(map(repr, RENDER_MODES))}")
    return render_mode


class _RunView:
    """Run ``b`` of a ``Runs``, seen as the ``Simulation`` the viewer's ``scene`` and ``encode`` read."""

    def __init__(self, runs, b: int, names: list[str]):
        self.config, self.behaviour_names = runs.config, names
        self.world = runs.worlds[b]
        self.seed = int(runs.seeds[b])
        self.clock = int(self.world.clock[0])


class ArenaRenderer:
    """Draws run ``b`` of ``runs`` as the movie does; one matplotlib figure, built on the first call."""

    def __init__(self, runs):
        self.runs = runs
        self.names = behaviour_table(runs.config)[2]
        self.picture: ArenaPicture | None = None

    def rgb(self, b: int = 0) -> np.ndarray:
        """[height, width, 3] uint8: run ``b`` now."""
        view = _RunView(self.runs, b, self.names)
        if self.picture is None:
            self.picture = ArenaPicture(scene(view), RENDER_WIDTH_PX, self.runs.steps)
        self.picture.draw(decode(encode(view), len(self.names)), seed=view.seed)
        return self.picture.rgb()


class Rebuilt:
    """Pickled and deep-copied as its construction arguments and its random generators (``_CARRIED``),
    rebuilt on unpickling.  Must come before the environment base class (its ``__new__`` records the
    arguments, so the classes' ``__init__`` need not)."""

    #: Attributes that hold the random streams a copy continues.
    _CARRIED: tuple[str, ...] = ("_np_random", "_np_random_seed")

    def __new__(cls, *args, **kwargs):
        self = super().__new__(cls)
        self._built_with = (args, kwargs)
        return self

    def _carried(self) -> dict:
        return {name: getattr(self, name) for name in self._CARRIED if hasattr(self, name)}

    def _carry(self, values: dict) -> None:
        for name, value in values.items():
            setattr(self, name, value)

    def __getstate__(self) -> dict:
        args, kwargs = self._built_with
        return {"args": args, "kwargs": kwargs, "carried": self._carried()}

    def __setstate__(self, state: dict) -> None:
        self._built_with = (state["args"], state["kwargs"])
        type(self).__init__(self, *state["args"], **state["kwargs"])
        self._carry(state["carried"])
