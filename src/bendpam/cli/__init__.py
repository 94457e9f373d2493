"""The ``bendpam`` command line: one module per group of commands, parsing and printing only.

* :mod:`.app`: the Typer app and :func:`main` (errors, interrupts, exit codes);
* :mod:`.options`: shared options and value parsing;
* :mod:`.predict`: ``predict``, ``curve``, ``stresses``, ``actuator``, ``demo``;
* :mod:`.lab`: ``process``, ``simulate-test``, ``inspect``;
* :mod:`.identify`: ``fit``, ``fit-material``;
* :mod:`.sweep`: ``sweep``;
* :mod:`.design`: ``finger``, ``grasp``, ``wrist``;
* :mod:`.hand`: ``hand`` (the soft humanoid hand, Kapandji test);
* :mod:`.inverse`: ``design`` (inverse design from targets);
* :mod:`.report`: ``report``;
* :mod:`.export`: ``export mujoco`` (a finger or gripper as a MuJoCo model).

The command modules are imported when the app's commands are first read (``typer.main.get_command(app)``, the
CLI reference, ``app()``), and :func:`main` imports the module of the command it runs only:
``bendpam --help`` imports none of them (:class:`~bendpam.cli.app.LazyTyper`).
"""

from __future__ import annotations

from bendpam.cli.app import app, main

__all__ = ["app", "main"]
