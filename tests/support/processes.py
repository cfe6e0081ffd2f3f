"""Starting a process the tests or benchmarks run with its output bounded, and stopping it
by its pid."""
import os
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


def run_bounded(command, folder, seconds=120):
    """Runs `command` to its end with its standard output and error in files of `folder`
    (each at most MAX_LOG_BYTES), killed by its pid after `seconds`; returns a
    subprocess.CompletedProcess with both outputs as text."""
    paths = [os.path.join(folder, "run-%d.%s" % (os.getpid(), name)) for name in ("out", "err")]
    with open(paths[0], "w") as out, open(paths[1], "w") as err:
        process = subprocess.Popen(["prlimit", "--fsize=%d" % MAX_LOG_BYTES, *command],
                                   stdout=out, stderr=err)
        try:
            process.wait(seconds)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
            raise
    texts = []
    for path in paths:
        with open(path) as f:
            texts.append(f.read())
        os.remove(path)
    return subprocess.CompletedProcess(command, process.returncode, texts[0], texts[1])
