"""Stopping a process the tests or benchmarks started, by its pid."""
import signal
import subprocess


def interrupt(process, seconds=30):
    """SIGINT, as Ctrl-C would, then SIGKILL if it has not exited after `seconds`."""
    if process is None or process.poll() is not None:
        return
    process.send_signal(signal.SIGINT)
    try:
        process.wait(seconds)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
