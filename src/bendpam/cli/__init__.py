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
"""

from __future__ import annotations

from bendpam.cli import design, export, hand, identify, inverse, lab, predict, report, sweep  # noqa: F401  (registers the commands)
from bendpam.cli.app import app, main
from bendpam.cli.options import use_bendpam_commands

report.register(app)
design.register(app)
hand.register(app)
use_bendpam_commands(app)  # one grammar for lists, --force where a command writes, readable help

__all__ = ["app", "main"]
