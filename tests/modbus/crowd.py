"""A crowd of other Modbus TCP clients for the connection-policy test, in a process of its
own so that its threads do not slow down the test's PLC: for SECONDS it runs

- 50 pollers from 127.0.0.1, each reading the block every 20 ms, 10 times a connection,
  and reconnecting 50 ms after its connection ends, is refused or closed;
- bursts of 50 idle connections from 127.0.0.1, a new burst every 1.5 s;
- connections that send bytes that are not Modbus TCP, or half a request and then one
  byte every 0.2 s (slowloris);
- connections from 127.0.0.3, which `allow` leaves out.

Then it prints one JSON line of the pollers' counts: reads answered, connections closed
(refused or closed later), connections or reads that failed.

usage: crowd.py PORT SECONDS
"""
import json
import socket
import struct
import sys
import threading
import time

POLLERS = 50
READS_PER_CONNECTION = 10
BURST = 50
BURST_PERIOD_S = 1.5
READ = struct.pack(">HHHBBHH", 1, 0, 6, 1, 3, 0, 11)
NOT_MODBUS = [
    struct.pack(">HHHBBHH", 1, 1, 6, 1, 3, 0, 11),  # protocol id 1
    struct.pack(">HHHB", 1, 0, 0, 1),  # length 0
    struct.pack(">HHHB", 1, 0, 0xFFFF, 1) + b"\0" * 64,  # huge length
    struct.pack(">HHHBBB", 1, 0, 3, 1, 0x83, 2),  # a response, not a request
    b"GET / HTTP/1.1\r\nHost: plc\r\n\r\n",
]


class Counts:
    def __init__(self):
        self.lock = threading.Lock()
        self.values = {"answered": 0, "closed": 0, "failed": 0}

    def add(self, name):
        with self.lock:
            self.values[name] += 1


def connect(port, source="127.0.0.1"):
    return socket.create_connection(("127.0.0.1", port), timeout=1, source_address=(source, 0))


def poller(port, deadline, counts):
    while time.monotonic() < deadline:
        try:
            with connect(port) as connection:
                for _ in range(READS_PER_CONNECTION):
                    connection.sendall(READ)
                    answer = connection.recv(64)
                    if not answer:
                        counts.add("closed")
                        break
                    counts.add("answered")
                    time.sleep(0.02)
        except OSError:
            counts.add("failed")
        time.sleep(0.05)


def idle_bursts(port, deadline):
    held = []
    while time.monotonic() < deadline:
        for connection in held:
            connection.close()
        held = []
        for _ in range(BURST):
            try:
                held.append(connect(port))
            except OSError:
                pass
        time.sleep(BURST_PERIOD_S)
    for connection in held:
        connection.close()


def not_modbus(port, deadline):
    while time.monotonic() < deadline:
        for garbage in NOT_MODBUS:
            try:
                with connect(port) as connection:
                    connection.sendall(garbage)
                    connection.recv(64)
            except OSError:
                pass
        time.sleep(0.05)


def slowloris(port, deadline):
    while time.monotonic() < deadline:
        try:
            with connect(port) as connection:
                connection.sendall(READ[:3])
                for byte in READ[3:] * 100:
                    if time.monotonic() >= deadline:
                        break
                    time.sleep(0.2)
                    connection.sendall(bytes([byte]))
        except OSError:
            pass


def outsider(port, deadline):
    while time.monotonic() < deadline:
        try:
            with connect(port, source="127.0.0.3") as connection:
                connection.sendall(READ)
                connection.recv(64)
        except OSError:
            pass
        time.sleep(0.1)


def main():
    port, seconds = int(sys.argv[1]), float(sys.argv[2])
    deadline = time.monotonic() + seconds
    counts = Counts()
    threads = [threading.Thread(target=poller, args=(port, deadline, counts))
               for _ in range(POLLERS)]
    threads += [threading.Thread(target=job, args=(port, deadline))
                for job in (idle_bursts, not_modbus, slowloris, outsider)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    print(json.dumps(counts.values))


if __name__ == "__main__":
    main()
