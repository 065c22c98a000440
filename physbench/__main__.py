"""``python -m physbench`` and the ``physbench`` script (its entry point is :func:`main`): the
first physbench code the process runs, so that Ctrl-C is one line and status 130 from here on,
even while the command's modules are still being imported."""

import os
import signal
import sys


def _interrupted_while_starting(signum: int, frame: object) -> None:
    """The SIGINT handler until :func:`main` hands over to the command: nothing has been done
    yet that needs unwinding, so stop at once, as the command would."""
    os.write(2, b"physbench: interrupted\n")
    os._exit(130)


signal.signal(signal.SIGINT, _interrupted_while_starting)


def _redeliver_swallowed_interrupt(unraisable: "sys.UnraisableHookArgs") -> None:
    """Installed as :data:`sys.unraisablehook` while the command runs: Python calls it for an
    exception it cannot raise, e.g. one inside a finalizer. A Ctrl-C that lands in pymunk's
    space finalizer (an ``ffi.gc`` callback) would be dropped there and the command would run on,
    so the signal is sent again a moment later, when the finalizer has returned."""
    if unraisable.exc_type is not None and issubclass(unraisable.exc_type, KeyboardInterrupt):
        import threading

        timer = threading.Timer(0.05, os.kill, (os.getpid(), signal.SIGINT))
        timer.daemon = True
        timer.start()
        return
    sys.__unraisablehook__(unraisable)


#: The status the process ends with; 1 until :func:`main` returns (an exception escaped it).
_status = 1


def main() -> int:
    """Called once per process, by the ``physbench`` script or ``python -m physbench``; runs the
    command in :data:`sys.argv`. The process then ends without the interpreter's teardown
    (:mod:`physbench.teardown`)."""
    global _status
    from physbench.teardown import skip_at_exit

    skip_at_exit(lambda: _status)
    from physbench.cli import main as run_command

    try:
        # From here Ctrl-C raises KeyboardInterrupt, so the command cleans up (saves finished
        # cells, ...) and run_command turns it into the line and 130.
        signal.signal(signal.SIGINT, signal.default_int_handler)
        sys.unraisablehook = _redeliver_swallowed_interrupt
        _status = run_command()
    except SystemExit as exc:  # argparse's usage errors and --help
        _status = exc.code if isinstance(exc.code, int) else int(exc.code is not None)
        raise
    except KeyboardInterrupt:  # before run_command's own guard, or re-raised by --debug
        _status = 130
        if "--debug" in sys.argv[1:]:
            raise
        print("physbench: interrupted", file=sys.stderr)
    return _status


if __name__ == "__main__":
    raise SystemExit(main())
