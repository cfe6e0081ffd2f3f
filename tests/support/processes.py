"""Starting a process the tests or benchmarks run with its output bounded, and stopping it
by its pid."""
import signal
import subprocess

# A log larger than this is a runaway writer: the process gets SIGXFSZ.
MAX_LOG_BYTES = 5_000_000


def start_logged(command, log_path):
    """`command` with its standard output and error in the file `log_path`, which it may
    not grow beyond MAX_LOG_BYTES (prlimit --fsize)."""
    with open(log_path, "w") as log:
        return subprocess.Popen(["prlimit", "--fsize=%d" % MAX_LOG_BYTES, *command],
                                stdout=log, stderr=log)


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
