"""``bendpam finger``, ``grasp`` and ``wrist`` (the implementation is being moved here from cli_design)."""

from ..cli_design import register

__all__ = ["register"]
