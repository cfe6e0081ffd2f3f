"""TCP ports for servers that tests start: chosen outside the kernel's ephemeral range, so
that no outgoing connection of a test running beside it (some open thousands) can take
the port between choosing it and the server's bind."""
import random
import socket
import time


def _ephemeral_range():
    try:
        with open("/proc/sys/net/ipv4/ip_local_port_range") as f:
            low, high = (int(word) for word in f.read().split())
            return low, high
    except (OSError, ValueError):
        return 32768, 60999


def free_port():
    """A port that nothing listens on or holds now, below the ephemeral range."""
    low, _ = _ephemeral_range()
    first = 10000 if low > 12000 else 1024
    for _ in range(200):
        port = random.randrange(first, low)
        with socket.socket() as probe:
            try:
                probe.bind(("0.0.0.0", port))
                return port
            except OSError:
                continue
    raise AssertionError("no free port in %d..%d" % (first, low - 1))


def wait_for_port(port, process=None, timeout=90.0):
    """Until something listens on `port`, or `process` ends (then its exit code and
    stderr are the error)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and (process is None or process.poll() is None):
        try:
            socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
            return
        except OSError:
            time.sleep(0.05)
    if process is not None and process.poll() is not None:
        raise AssertionError("nothing listened on port %d before the run ended (exit %d): %s"
                             % (port, process.returncode, process.communicate(timeout=60)[1]))
    raise AssertionError("nothing listens on port %d" % port)
