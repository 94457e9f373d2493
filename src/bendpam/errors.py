"""The exceptions bendpam raises for problems a user can fix.

Every message is one line that names the value, key, file or line at fault and what was
expected; none names a command-line flag (the library does not know how it was called).  The
command line turns these into ``bendpam: error: ...`` and exit status 2; anything else reaching
it is a bug and is reported as one.

* :class:`BendpamError`: the base class.
* :class:`InputError` (also a :class:`ValueError`): a value out of range, an unknown option or
  key, inconsistent arguments.
* :class:`InputTypeError` (an :class:`InputError`, also a :class:`TypeError`): an argument of the
  wrong kind (a string or ``None`` where an actuator is expected).
* :class:`FileFormatError` (an :class:`InputError`): a file that cannot be read or understood;
  the message starts with the file name and, where it applies, the line.
* :class:`ProcessingError` (an :class:`InputError`): a test that reads but cannot be processed
  (too few cycles, no reversal, ...).
* :class:`NoEquilibrium`: no physical answer exists (above a fold, beyond lock-up).
* :class:`FitError`: identification failed for a reason that lies in the data (curves that
  cannot separate two parameters, too few points), explained in terms of the data.

Three warning classes live here too: :class:`PlausibilityWarning`, for a result that the models
computed but that lies beyond a physical plausibility bound (docs/plausibility.md);
:class:`ModelMismatchWarning`, for an actuator used with another model than the one its constants
were identified with; :class:`OutsideTestedRangeWarning`, for a fitted actuator used at pressures
outside those it was tested at.
"""

from __future__ import annotations

__all__ = ["BendpamError", "FileFormatError", "FitError", "InputError", "InputTypeError", "ModelMismatchWarning",
           "NoEquilibrium", "OutsideTestedRangeWarning", "PlausibilityWarning", "ProcessingError", "warn_user"]

import sys
import warnings
from types import FrameType


def warn_user(message: str, category: type[Warning] = UserWarning) -> None:
    """``warnings.warn(message, category)`` located at the user's call: the first frame outside bendpam.

    Python's default filter then shows a warning once per line of the user's code, however deep in
    bendpam it was raised.

    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warn_user("a word of caution")
    >>> str(caught[0].message)
    'a word of caution'
    """
    level = 1
    frame: FrameType | None = sys._getframe(1)
    while frame is not None and (frame.f_globals.get("__name__", "") + ".").startswith("bendpam."):
        frame, level = frame.f_back, level + 1
    warnings.warn(message, category, stacklevel=level + 1)


class BendpamError(Exception):
    """Base class of the errors that a user can act on (one-line messages).

    Examples
    --------
    >>> import bendpam
    >>> try:
    ...     bendpam.physics.presets.get("xx-pam")
    ... except bendpam.BendpamError as exc:
    ...     print(type(exc).__name__, "-", exc)
    InputError - unknown preset 'xx-pam'; choose one of: be-pam, bc-pam
    """


class InputError(BendpamError, ValueError):
    """A bad argument or option value: out of range, unknown, of the wrong type or inconsistent.

    Examples
    --------
    >>> import bendpam
    >>> bendpam.blocked_moment(bendpam.physics.presets.be_pam(), -10.0)
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: pressure_kpa = -10 kPa at index 0 is below zero; allowed range [0, 2000] kPa (gauge)
    """


class InputTypeError(InputError, TypeError):
    """An argument of the wrong kind, e.g. ``None`` or a preset's name where an Actuator is expected.

    It is an :class:`InputError` (one line, ``bendpam: error: ...`` on the command line) and a
    :class:`TypeError`, so code written against the plain ``TypeError`` of earlier versions still
    catches it.

    Examples
    --------
    >>> import bendpam
    >>> try:
    ...     bendpam.blocked_moment("be-pam", 200.0)
    ... except bendpam.InputError as exc:
    ...     print(isinstance(exc, TypeError), "-", exc)
    True - actuator = 'be-pam' must be a bendpam.Actuator (e.g. bendpam.physics.presets.get('be-pam')), got str
    """


class PlausibilityWarning(UserWarning):
    """A computed result beyond a physical plausibility bound (docs/plausibility.md).

    The inputs were each within their plausible ranges, but the result is not what a bending PAM
    can do (a free-bending angle past a full turn, a pneumatic moment far above the McKibben
    bound), so the model is being used outside what it describes.

    Examples
    --------
    >>> import warnings, bendpam
    >>> long = bendpam.physics.presets.be_pam().replace(L0_mm=1000.0)
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     _ = bendpam.free_curvature(long, 200.0)
    >>> caught[0].category.__name__, str(caught[0].message)[:59]
    ('PlausibilityWarning', 'free-bending angle 775 deg at 200 kPa is beyond a full turn')
    """


class ModelMismatchWarning(UserWarning):
    """An actuator evaluated with another model than the one its constants were identified with.

    Table 3 gives different constants for each model; an actuator records its model
    (:attr:`bendpam.Actuator.model`) and every function that takes it uses that model unless told
    otherwise.  Asking for the other one explicitly warns in one line naming both.

    Examples
    --------
    >>> import warnings, bendpam
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     _ = bendpam.blocked_moment(bendpam.physics.presets.be_pam("force_balance"), 200.0, "energy")
    >>> caught[0].category.__name__, str(caught[0].message)
    ('ModelMismatchWarning', 'BE-PAM (paper, force-balance constants): its constants were identified with the
    force-balance model; using them with the energy model')
    """


class OutsideTestedRangeWarning(UserWarning):
    """A fitted actuator (or fit) used at a pressure outside the pressures it was tested at.

    The prediction is an extrapolation of the identified constants.

    Examples
    --------
    >>> import warnings, bendpam
    >>> act = bendpam.physics.presets.be_pam().replace(tested_pressure_kpa=(100.0, 200.0))
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     _ = bendpam.blocked_moment(act, 250.0)
    >>> caught[0].category.__name__, str(caught[0].message)[:73]
    ('OutsideTestedRangeWarning', 'pressure 250 kPa is outside the tested range [100, 200] kPa of BE-PAM (...')
    """


class FileFormatError(InputError):
    """A file that cannot be read or understood (message starts with the file name).

    Examples
    --------
    >>> import bendpam
    >>> bendpam.Actuator.from_toml("no-such-file.toml")
    Traceback (most recent call last):
    ...
    bendpam.errors.FileFormatError: no-such-file.toml: actuator file not found
    """


class ProcessingError(InputError):
    """A raw test that reads but cannot be processed (message starts with the file name).

    Examples
    --------
    >>> import numpy as np
    >>> from bendpam.lab.processing import process_series
    >>> process_series(np.arange(10.0), np.zeros(10), np.zeros(10), 150.0)
    Traceback (most recent call last):
    ...
    bendpam.errors.ProcessingError: <data>: only 10 samples; a cyclic test needs at least 20
    """


class NoEquilibrium(BendpamError, ValueError):
    """No physical equilibrium exists for the request (e.g. above a fold or beyond lock-up).

    Examples
    --------
    The paper's BC-PAM folds at 134 kPa (energy-model constants), so a finger of it has no free
    shape at 150 kPa:

    >>> import bendpam
    >>> from bendpam.design import Finger, linear_tip_compliance
    >>> try:
    ...     linear_tip_compliance(Finger(bendpam.physics.presets.bc_pam()), 150.0)
    ... except bendpam.NoEquilibrium as exc:
    ...     print(exc)
    pressure_kpa = 150 kPa has no free-bending equilibrium: fold of the moment-curvature curve ...
    """


class FitError(BendpamError, ValueError):
    """Identification failed for a reason that lies in the data.

    Examples
    --------
    >>> import numpy as np
    >>> from bendpam.identify.tension import fit_tension
    >>> stretch = np.linspace(1.0, 1.5, 10)
    >>> fit_tension(stretch, -100.0 * (stretch - 1.0))      # stress falling with stretch
    Traceback (most recent call last):
    ...
    bendpam.errors.FitError: tension data: no positive shear modulus fits: ...
    """
