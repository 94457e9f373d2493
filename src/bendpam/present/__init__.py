"""The presentation layer: every figure (:mod:`bendpam.present.figures`) and the report
(:mod:`bendpam.present.report`).

Computation never imports this package; results reach their figures lazily through
:func:`bendpam.infra.accessors.present`, the way xarray's ``.plot`` accessor does.
"""
