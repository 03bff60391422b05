"""Progress bars (issue 16, item 3): tqdm on a terminal's stderr, nothing on a pipe, never on
stdout (``--json`` stays parseable)."""

from __future__ import annotations

import io
import json
import os
import pty
import subprocess
import sys

from jointlock.progress import Progress, in_notebook

SAMPLING = [sys.executable, "-m", "jointlock", "halt-config", "halt7", "--lock", "4=0", "--samples", "20000", "--json"]


def _run(stderr_tty: bool) -> tuple[str, str]:
    """The command's stdout (a pipe) and stderr (a new pseudo-terminal, or a pipe)."""
    env = {**os.environ, "MPLBACKEND": "Agg"}
    if not stderr_tty:
        proc = subprocess.run(SAMPLING, capture_output=True, text=True, env=env, timeout=300)
        return proc.stdout, proc.stderr
    main, side = pty.openpty()
    proc = subprocess.Popen(SAMPLING, stdout=subprocess.PIPE, stderr=side, env=env)
    os.close(side)
    err = b""
    while True:
        try:
            chunk = os.read(main, 4096)
        except OSError:  # the other side closed
            break
        if not chunk:
            break
        err += chunk
    out = proc.communicate(timeout=300)[0]
    os.close(main)
    return out.decode(), err.decode(errors="replace")


def test_a_terminal_gets_a_bar_and_stdout_stays_json():
    out, err = _run(stderr_tty=True)
    assert json.loads(out)["samples"] == 20000
    assert "sampling" in err and "100%" in err and "20000/20000" in err


def test_a_pipe_gets_no_bar():
    out, err = _run(stderr_tty=False)
    assert json.loads(out)["samples"] == 20000
    assert "sampling" not in err and "%|" not in err


def test_a_bar_asked_for_is_drawn_on_the_given_stream_with_its_note():
    stream = io.StringIO()
    with Progress(4, "cases", enabled=True, stream=stream, unit="cases") as bar:
        bar.update(4, note="1 failed")
    text = stream.getvalue()
    assert "cases: 100%" in text and "4/4" in text and "1 failed" in text


def test_outside_a_notebook_none_is_detected():
    assert not in_notebook()  # pytest is no Jupyter kernel
