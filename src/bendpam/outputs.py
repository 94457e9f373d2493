"""Deprecated alias of :mod:`bendpam.infra.outputs` (moved in 0.4; this alias is removed in 0.5)."""

from bendpam._compat import alias_module

alias_module(__name__, "bendpam.infra.outputs")
