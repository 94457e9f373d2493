"""The address of a Dask scheduler, read and checked before any work.

:func:`parse_scheduler_address` accepts ``tcp://HOST:PORT`` (or ``tls://``, ``ws://``, ``wss://``,
``ucx://``), ``HOST:PORT`` (TCP) or the path of a scheduler file (the JSON file that ``dask
scheduler --scheduler-file`` writes), and refuses anything else in one line.
:func:`probe_scheduler` asks the scheduler who it is, within :data:`~bendpam.infra.budgets.SCHEDULER_TIMEOUT_S`
seconds: a host that does not answer, or answers but not as a Dask scheduler (a web server, a
Dask worker), is refused in one line instead of hanging the command (Dask's own client waits
without end for a server that accepts the connection and then says nothing).

The probe imports :mod:`distributed` only when it runs.
"""

from __future__ import annotations

import asyncio
import json
import os
import re
from typing import Any

from bendpam.errors import InputError
from bendpam.infra.budgets import SCHEDULER_TIMEOUT_S, read_input_bytes

__all__ = ["SCHEDULER_SCHEMES", "parse_scheduler_address", "probe_scheduler"]

#: The Dask communication protocols an address may name (``inproc``: a cluster in this process).
SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx", "inproc")
_HOST = re.compile(r"^(?:\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9](?:[A-Za-z0-9._-]{0,251}[A-Za-z0-9])?)$")
_EXPECTED = "expected tcp://HOST:PORT, HOST:PORT or a scheduler file (the JSON file a Dask scheduler writes)"


def _host_port(rest: str) -> str | None:
    """``HOST:PORT`` checked (None if it is not one), with the port as a number 1-65535."""
    host, sep, port = rest.rpartition(":")
    if not sep or not _HOST.match(host) or not port.isdigit() or not 0 < int(port) < 65536:
        return None
    return f"{host}:{int(port)}"


def _from_file(path: str, name: str) -> str:
    data = read_input_bytes(path, "scheduler file")
    try:
        address = json.loads(data.decode("utf-8")).get("address")
    except (UnicodeDecodeError, ValueError, AttributeError, RecursionError):
        address = None
    if not isinstance(address, str):
        raise InputError(f"{name} {path!r}: not a Dask scheduler file (a JSON object with an \"address\")")
    return parse_scheduler_address(address, name=f"{name} {path!r}: its address", files=False)


def parse_scheduler_address(text: str, *, name: str = "scheduler", files: bool = True) -> str:
    """The address of a Dask scheduler as Dask takes it, from an address or a scheduler file.

    ``name`` names the value in messages; ``files`` allows a scheduler file.  Raises
    :class:`~bendpam.errors.InputError` (one line) for anything else.

    >>> parse_scheduler_address("tcp://10.0.0.5:8786"), parse_scheduler_address("cluster.local:8786")
    ('tcp://10.0.0.5:8786', 'tcp://cluster.local:8786')
    >>> parse_scheduler_address("nonsense")
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: scheduler 'nonsense': not a Dask scheduler address; expected tcp://HOST:PORT, ...
    """
    text = str(text).strip()
    scheme, sep, rest = text.partition("://")
    if sep:
        hp = _host_port(rest.rstrip("/"))
        if scheme.lower() not in SCHEDULER_SCHEMES:
            raise InputError(f"{name} {text!r}: unknown protocol {scheme!r}; choose {', '.join(SCHEDULER_SCHEMES)}")
        if scheme.lower() == "inproc" and rest:
            return text
        if hp is None:
            raise InputError(f"{name} {text!r}: expected {scheme}://HOST:PORT with a port from 1 to 65535")
        return f"{scheme.lower()}://{hp}"
    hp = _host_port(text)
    if hp is not None:
        return f"tcp://{hp}"
    if files and text and (os.path.lexists(text) or text.lower().endswith(".json")):
        return _from_file(text, name)
    raise InputError(f"{name} {text!r}: not a Dask scheduler address; {_EXPECTED}")


async def _identity(address: str, timeout_s: float) -> Any:
    from distributed.comm import connect

    comm = await connect(address, timeout=timeout_s)
    try:
        await comm.write({"op": "identity", "reply": True})
        return await comm.read()
    finally:
        await comm.close()


def _ask(address: str, timeout_s: float) -> Any:
    """The scheduler's identity, in a fresh event loop (in a thread: the caller may run one already)."""
    from concurrent.futures import ThreadPoolExecutor

    def run():
        return asyncio.run(asyncio.wait_for(_identity(address, timeout_s), timeout_s))

    with ThreadPoolExecutor(1, thread_name_prefix="bendpam-probe") as pool:
        return pool.submit(run).result()


def probe_scheduler(address: str, timeout_s: float = SCHEDULER_TIMEOUT_S) -> dict:
    """Ask the Dask scheduler at ``address`` who it is; refuse in one line if it does not answer as one.

    Returns the scheduler's identity (a dict with ``"type": "Scheduler"``, its ``"address"`` and
    ``"workers"``).  Raises :class:`~bendpam.errors.InputError` when nothing answers within
    ``timeout_s`` seconds, when the answer is not Dask's, or when :mod:`distributed` is missing.

    >>> probe_scheduler("tcp://127.0.0.1:9", timeout_s=0.2)     # the discard port: nothing answers
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: no Dask scheduler answered at tcp://127.0.0.1:9 within 0.2 s...
    """
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise InputError("a Dask scheduler needs distributed: pip install 'bendpam[distributed]'") from None
    try:
        info = _ask(address, float(timeout_s))
    except (TimeoutError, OSError):  # silent, refused or unreachable
        raise InputError(f"no Dask scheduler answered at {address} within {timeout_s:g} s") from None
    except Exception as exc:  # the peer spoke, but not Dask's protocol
        raise InputError(f"{address} answered, but not as a Dask scheduler ({type(exc).__name__})") from None
    kind = info.get("type") if isinstance(info, dict) else None
    if kind != "Scheduler":
        raise InputError(f"{address} answered, but as a Dask {kind or 'peer of an unknown kind'}, not a scheduler")
    return info
