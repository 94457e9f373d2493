"""The presentation layer: every figure (:mod:`bendpam.present.figures`) and the report
(:mod:`bendpam.present.report`).

Computation never imports this package; results reach their figures lazily through
:func:`bendpam.infra.accessors.present`, the way xarray's ``.plot`` accessor does.
"""


def __getattr__(name: str):
    """Submodules on first use (``bendpam.present.figures``), as an import statement would give them."""
    import importlib
    import importlib.util

    if importlib.util.find_spec(f"{__name__}.{name}") is not None:
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
