"""How a swarm's walks are run: the walker's options as a walking family's Config holds them
(its ``walker`` field) and hands them to :func:`~jaxswarm.swarm.walking.loop.walk` unread. They
change no result: only the memory of a walk, how often a run is made again because a walk
overflowed its log, and which implementation walks."""
from __future__ import annotations

import dataclasses

from jaxswarm.swarm.walking.log import ROOM_FOR_EVERY_MOVE

IMPLEMENTATIONS = ("lanes", "native")
"""The walker's implementations: the vectorised lanes (the reference) and the native loop on CPU
(:mod:`jaxswarm.swarm.walking.native`), which walk the same walks bit for bit."""


@dataclasses.dataclass(frozen=True)
class WalkerOptions:
    """The walker's options.

    Attributes:
      log_moves: moves per agent, on average, a walk's log has room for; None:
        :func:`~jaxswarm.swarm.walking.log.room_blocks` (room for every move on small maps).
      implementation: one of :data:`~jaxswarm.swarm.walking.options.IMPLEMENTATIONS`; None:
        the environment's choice
        (:func:`jaxswarm.swarm.walking.native.implementation`).
    """

    log_moves: int | None = None
    implementation: str | None = None

    def __post_init__(self):
        if self.log_moves is not None and self.log_moves < 1:
            raise ValueError(f"log_moves must be at least 1, got {self.log_moves}")
        if self.implementation is not None and self.implementation not in IMPLEMENTATIONS:
            raise ValueError(f"implementation must be one of {', '.join(IMPLEMENTATIONS)}, got "
                             f"{self.implementation!r}")

    def with_room(self) -> WalkerOptions:
        """These options with room for every agent's whole step budget: no walk overflows."""
        return dataclasses.replace(self, log_moves=ROOM_FOR_EVERY_MOVE)


EVERY_MOVE = WalkerOptions(log_moves=ROOM_FOR_EVERY_MOVE)
"""Walker options with room for every agent's whole step budget: no walk overflows."""
