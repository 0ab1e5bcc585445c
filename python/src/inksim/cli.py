"""Running inksim from Python, through its command-line program.

``inksim.run("scene.toml")`` runs ``inksim run scene.toml`` in a subprocess
(and, for a study, ``inksim merge`` afterwards) and returns where the results
went. This package calls the CLI rather than binding the Rust crate because:

- users need no build step: ``pip install ./python`` installs pure Python,
  with no Rust toolchain, no compiled extension per Python version and no
  HDF5 library to link twice (h5py brings its own, the binary its own);
- the CLI is the tested interface: the Rust test suite runs it end to end,
  and its files (HDF5, PNG) are the contract this package reads, so Python
  sees exactly what a shell user sees;
- a run is seconds to hours of compute in its own process: nothing is lost
  by not sharing memory, and Ctrl-C, threads (``--threads``) and the atomic
  writes behave as documented.

The binary is found, in this order: the ``INKSIM_BIN`` environment variable
(a path to the executable), ``inksim`` on ``PATH``, and finally ``cargo run
--release --`` in an inksim checkout (found by walking up from the working
directory and from this file; compiles the crate on first use).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import threading
from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Union

__all__ = ["run", "find_binary", "InksimError", "InksimNotFound", "RunOutput"]

PathLike = Union[str, "os.PathLike[str]"]


class InksimNotFound(FileNotFoundError):
    """No inksim binary: not in ``INKSIM_BIN``, not on ``PATH``, no checkout with cargo."""


class InksimError(RuntimeError):
    """The inksim CLI exited with an error; ``stderr`` holds its message."""

    def __init__(self, message: str, command: Sequence[str], returncode: int,
                 stdout: str, stderr: str):
        super().__init__(message)
        self.command = list(command)
        self.returncode = returncode
        self.stdout = stdout
        self.stderr = stderr


@dataclass
class RunOutput:
    """What a run produced.

    ``kind`` is ``"scene"`` or ``"study"``; ``path`` the result file (scene)
    or ``summary.h5`` (study, when merged; else ``None``); ``stdout`` and
    ``stderr`` the CLI's output; ``command`` what ran."""

    kind: str
    path: Optional[str]
    command: List[str]
    stdout: str = ""
    stderr: str = ""
    extra: dict = field(default_factory=dict)

    def open(self):
        """Open the result (``open_result``) or the merged study (``open_study``)."""
        if self.path is None:
            raise ValueError("nothing to open: the study was not merged (run(..., merge=True))")
        if self.kind == "study":
            from .study import open_study

            return open_study(self.path)
        from .result import open_result

        return open_result(self.path)


def _is_inksim_checkout(d: str) -> bool:
    cargo = os.path.join(d, "Cargo.toml")
    if not os.path.isfile(cargo):
        return False
    try:
        with open(cargo, encoding="utf-8") as fh:
            return re.search(r'^\s*name\s*=\s*"inksim"\s*$', fh.read(), re.M) is not None
    except OSError:
        return False


def _find_checkout() -> Optional[str]:
    for start in (os.getcwd(), os.path.dirname(os.path.abspath(__file__))):
        d = start
        while True:
            if _is_inksim_checkout(d):
                return d
            parent = os.path.dirname(d)
            if parent == d:
                break
            d = parent
    return None


def find_binary() -> List[str]:
    """The command prefix that runs inksim (a list for ``subprocess``).

    Raises :class:`InksimNotFound` saying what was tried."""
    env = os.environ.get("INKSIM_BIN")
    if env:
        if os.path.isfile(env) and os.access(env, os.X_OK):
            return [env]
        raise InksimNotFound(f"INKSIM_BIN={env}: not an executable file")
    which = shutil.which("inksim")
    if which:
        return [which]
    root = _find_checkout()
    cargo = shutil.which("cargo")
    if root and cargo:
        return [cargo, "run", "--release", "--quiet",
                "--manifest-path", os.path.join(root, "Cargo.toml"), "--"]
    raise InksimNotFound(
        "no inksim binary: set INKSIM_BIN to its path, put `inksim` on PATH "
        "(cargo install --path . in the repository), or run from an inksim checkout with cargo"
    )


def _call(cmd: List[str], cwd: Optional[str], echo: bool):
    if not echo:
        p = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           stdin=subprocess.DEVNULL, text=True, encoding="utf-8", errors="replace")
        return p.returncode, p.stdout, p.stderr
    p = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         stdin=subprocess.DEVNULL, text=True, encoding="utf-8", errors="replace")
    out: List[str] = []
    err: List[str] = []

    def pump(src, sink, dst):
        for line in src:
            sink.append(line)
            dst.write(line)
            dst.flush()

    ts = [threading.Thread(target=pump, args=(p.stdout, out, sys.stdout)),
          threading.Thread(target=pump, args=(p.stderr, err, sys.stderr))]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    return p.wait(), "".join(out), "".join(err)


def _fail(what: str, cmd: List[str], rc: int, out: str, err: str) -> InksimError:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    msgs = [ln for ln in lines if ln.lower().startswith("error")] or lines[-5:]
    detail = "\n".join(msgs) if msgs else "(no message)"
    return InksimError(f"inksim {what} failed (exit {rc}): {detail}", cmd, rc, out, err)


def _found(pattern: str, text: str, cwd: Optional[str]) -> Optional[str]:
    m = re.search(pattern, text, re.M)
    if not m:
        return None
    p = m.group(1).strip()
    return p if os.path.isabs(p) else os.path.abspath(os.path.join(cwd or os.getcwd(), p))


def run(config_path: PathLike, output_dir: Optional[PathLike] = None, *,
        profile: Optional[str] = None, threads: Optional[int] = None,
        jobs: Optional[int] = None, shard: Optional[str] = None, merge: bool = True,
        cwd: Optional[PathLike] = None, echo: bool = False) -> RunOutput:
    """Run a scene or a study with the inksim CLI.

    - ``config_path``: scene or study TOML file;
    - ``output_dir``: ``--output-dir`` (scene: the result folder; study:
      instead of ``study.output_dir``); default: what the file says;
    - ``profile``, ``jobs``, ``shard``: study options (``--profile``,
      ``--jobs``, ``--shard I/N``); ``threads``: ``--threads``;
    - ``merge``: for a study, run ``inksim merge`` afterwards (default) so
      the returned path is ``summary.h5``;
    - ``cwd``: working directory of the run (relative paths in the file are
      relative to it); ``echo``: also print the CLI's output as it comes.

    Returns a :class:`RunOutput`; ``.open()`` reads the result. Raises
    ``FileNotFoundError`` for a missing config, :class:`InksimNotFound`
    without a binary, :class:`InksimError` when the CLI fails (its message
    in the exception text, its whole output in ``.stderr``).
    """
    cwd_s = os.fspath(cwd) if cwd is not None else None
    cfg = os.fspath(config_path)
    cfg_abs = cfg if os.path.isabs(cfg) else os.path.join(cwd_s or os.getcwd(), cfg)
    if not os.path.isfile(cfg_abs):
        raise FileNotFoundError(f"{cfg}: no such scene or study file (looked at {os.path.abspath(cfg_abs)})")
    base = find_binary()
    glob_opts: List[str] = []
    if threads is not None:
        glob_opts += ["--threads", str(int(threads))]
    opts: List[str] = []
    if output_dir is not None:
        opts += ["--output-dir", os.fspath(output_dir)]
    study_opts: List[str] = []
    if profile is not None:
        study_opts += ["--profile", profile]
    run_opts = list(study_opts)
    if jobs is not None:
        run_opts += ["--jobs", str(int(jobs))]
    if shard is not None:
        run_opts += ["--shard", str(shard)]
    cmd = base + glob_opts + ["run", cfg] + opts + run_opts
    rc, out, err = _call(cmd, cwd_s, echo)
    if rc != 0:
        raise _fail(f"run {cfg}", cmd, rc, out, err)
    result = _found(r"^results:\s*(.+)$", out, cwd_s)
    if result is not None:
        return RunOutput("scene", result, cmd, out, err)
    if not re.search(r"^study run:", out, re.M):
        raise InksimError(f"inksim run {cfg}: could not tell where the results went "
                          f"(no `results:` or `study run:` line in its output)", cmd, rc, out, err)
    if not merge:
        return RunOutput("study", None, cmd, out, err)
    mcmd = base + glob_opts + ["merge", cfg] + opts + study_opts
    mrc, mout, merr = _call(mcmd, cwd_s, echo)
    if mrc != 0:
        raise _fail(f"merge {cfg}", mcmd, mrc, mout, merr)
    summary = _found(r"^summary:\s*(.+)$", mout, cwd_s)
    return RunOutput("study", summary, cmd, out + mout, err + merr, extra={"merge_command": mcmd})
