"""Infrastructure beside the layers: output sets, atomic writes, signals, progress lines.

These modules import only the standard library, :mod:`bendpam.errors`, :mod:`bendpam.validate` and
:mod:`bendpam.version` (and :mod:`filelock`, lazily, for the locks of output targets), so every
layer may use them.  None imports a POSIX-only module at module level.

* :mod:`.outputs`: :class:`~.outputs.OutputSet`, :class:`~.outputs.OutputFile`,
  :class:`~.outputs.OutputGroup` (all-or-nothing outputs that replace only what bendpam wrote);
* :mod:`.manifest`: the manifest of a set, its checks when a set is replaced or read back;
* :mod:`.targets`: where an output may go (``~``, links, inputs, the home folder);
* :mod:`.signals`: SIGINT/SIGTERM as :class:`~.signals.Interrupted`, held sections, honest words;
* :mod:`.locks`: the portable lock of an output target;
* :mod:`.fsops`: temporaries, flushing, hashing and the folder swap;
* :mod:`.atomic`, :mod:`.progress`, :mod:`.accessors`, :mod:`.display` (short summaries of results);
* :mod:`.console`: what a console's encoding lacks (a Windows pipe has no Greek letters) in ASCII words.
"""


def __getattr__(name: str):
    """Submodules on first use (``bendpam.infra.outputs``), as an import statement would give them."""
    import importlib
    import importlib.util

    if importlib.util.find_spec(f"{__name__}.{name}") is not None:
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
