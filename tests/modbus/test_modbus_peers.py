"""modbus.output against real Modbus peers, in `tilth run`s of a known distance sequence
(testdistance.sequence) that also feeds sinks.csv:

- server mode: mbpoll and pymodbus poll Tilth; every block read must equal, register
  for register, the CSV row of the frame its frame counter names; the output goes stale
  when the source stops; the heartbeat keeps counting; bad requests get the documented
  exception codes, garbage and silent clients harm no one else.
- connections (server mode): a PLC polling every 20 ms through a crowd of 50 other
  pollers, idle bursts, garbage and slowloris senders is never disconnected and reads
  the right distance every time; idle clients are closed on time, addresses outside
  `allow` and clients beyond `max_clients` at once.
- client mode: Tilth writes into a pymodbus server standing in for the PLC, finds it
  when it comes up late, and again after it restarts.
"""
import csv
import json
import math
import os
import re
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time
import unittest

SUPPORT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "support")
sys.path.insert(0, SUPPORT)
from pymodbus_tcp import ModbusTcpClient  # noqa: E402
from ports import free_port, wait_for_port  # noqa: E402

TILTH = os.environ["TILTH_BIN"]
PLUGIN_DIR = os.environ["TILTH_TEST_PLUGIN_DIR"]
MBPOLL = os.environ["MBPOLL"]
PLC_SERVER = os.path.join(SUPPORT, "plc_server.py")
CROWD = os.environ["CROWD"]

# The register map (docs/modbus.md), offsets from base_register.
DISTANCE_HUNDREDTHS, DISTANCE_FLOAT, FRAME, STATUS, SOIL, CONFIDENCE, HEARTBEAT, AGE, CAUSE = (
    0, 2, 4, 6, 7, 8, 9, 10, 11)
COUNT = 12
CAUSE_TOO_LITTLE_SOIL = 1
VALID, CAMERA_OK, TOO_LITTLE_SOIL, STALE, PIPELINE_ERROR = 1, 2, 4, 8, 16

STALE_TIMEOUT_MS = 200
FRAMES = 60
FIRST_FRAME_ID = 65500  # the frame counter's high word changes during the run
INVALID_EVERY = 7


class TilthRun:
    """`tilth run` of the sequence into modbus.output and sinks.csv."""

    def __init__(self, tmp, modbus_params, source_params):
        self.csv_path = os.path.join(tmp, "distances.csv")
        self.graph = os.path.join(tmp, "graph.json")
        with open(self.graph, "w") as f:
            json.dump({
                "nodes": {
                    "source": {"type": "testdistance.sequence", "params": source_params},
                    "plc": {"type": "modbus.output", "params": modbus_params},
                    "csv": {"type": "sinks.csv", "params": {"path": self.csv_path}},
                },
                "edges": [["source.distance", "plc.distance"],
                          ["source.distance", "csv.distance"]],
            }, f)
        self.stderr_path = os.path.join(tmp, "stderr.txt")
        self.stderr_file = open(self.stderr_path, "w")
        self.process = subprocess.Popen(
            [TILTH, "run", self.graph], stdout=subprocess.DEVNULL,
            stderr=self.stderr_file, env=dict(os.environ, TILTH_PLUGIN_PATH=PLUGIN_DIR))

    def rows(self):
        """The complete CSV rows so far, by frame id."""
        if not os.path.exists(self.csv_path):  # the sink is not made yet
            return {}
        with open(self.csv_path) as f:
            return {int(row["index"]): row for row in csv.DictReader(f)
                    if row["truth_mm"] is not None}

    def wait_running(self, timeout=60):
        """Until Tilth says it runs the graph (its stop handlers are in place from its first
        line on): under ASan on a loaded machine a start takes seconds, and a SIGTERM before
        the handlers are installed kills it (-15) instead of stopping it."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and self.process.poll() is None:
            with open(self.stderr_path) as f:
                if "run: running " in f.read():
                    return
            time.sleep(0.02)
        code, log = self.stop()
        raise AssertionError("tilth did not start running the graph within %d s (exit %s): %s"
                             % (timeout, code, log[-2000:]))

    def stop(self):
        """SIGTERM; returns the exit code and what was logged."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGTERM)
        return self.wait()

    def wait(self):
        """Until it exits by itself; returns the exit code and what was logged. A run that
        has not exited in 20 s is killed, and the timeout raised."""
        try:
            code = self.process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
            raise
        self.stderr_file.close()
        with open(self.stderr_path) as f:
            return code, f.read()


def join32(words, word_order):
    high, low = words if word_order == "big" else reversed(words)
    return high << 16 | low


def decode(registers, word_order="big"):
    hundredths = join32(registers[DISTANCE_HUNDREDTHS:DISTANCE_HUNDREDTHS + 2], word_order)
    return {
        "hundredths": hundredths - (1 << 32) if hundredths & 0x80000000 else hundredths,
        "float_bits": join32(registers[DISTANCE_FLOAT:DISTANCE_FLOAT + 2], word_order),
        "frame": join32(registers[FRAME:FRAME + 2], word_order),
        "status": registers[STATUS],
        "soil": registers[SOIL],
        "confidence": registers[CONFIDENCE],
        "heartbeat": registers[HEARTBEAT],
        "age": registers[AGE],
        "cause": registers[CAUSE],
    }


def expected(row):
    """What the registers must say about a CSV row's frame (not stale)."""
    valid = row["valid"] == "1"
    distance = float(row["distance_mm"]) if valid else 0.0
    return {
        "hundredths": round(distance * 100),
        "float_bits": struct.unpack(">I", struct.pack(">f", distance))[0],
        "frame": int(row["index"]) & 0xFFFFFFFF,
        "status": (VALID if valid else TOO_LITTLE_SOIL) | CAMERA_OK,
        "soil": round(float(row["soil_fraction"]) * 10000),
        "confidence": round(float(row["confidence"]) * 1000),
        "cause": 0 if valid else CAUSE_TOO_LITTLE_SOIL,
    }


def pymodbus_read(port, address=0, count=COUNT, slave=1):
    client = ModbusTcpClient("127.0.0.1", port=port, timeout=2)
    try:
        client.connect()
        result = client.read_holding_registers(address, count, slave=slave)
        assert not result.isError(), result
        return list(result.registers)
    finally:
        client.close()


def mbpoll(port, address, count):
    """Reads holding registers once with mbpoll; (exit code, registers, output)."""
    result = subprocess.run(
        [MBPOLL, "-m", "tcp", "-a", "1", "-0", "-r", str(address), "-c", str(count), "-t", "4:hex",
         "-1", "-o", "1", "-p", str(port), "127.0.0.1"],
        capture_output=True, text=True, timeout=10)
    registers = [int(value, 16) for value in re.findall(r"^\[\d+\]:\s+0x([0-9A-F]{4})$",
                                                         result.stdout, re.M)]
    return result.returncode, registers, result.stdout + result.stderr


def request(connection, transaction, unit, pdu):
    """Sends one raw Modbus TCP request; returns the whole response frame."""
    connection.sendall(struct.pack(">HHHB", transaction, 0, len(pdu) + 1, unit) + pdu)
    return receive_frame(connection)


def receive_frame(connection):
    header = receive_exactly(connection, 7)
    length = struct.unpack(">H", header[4:6])[0]
    return header + receive_exactly(connection, length - 1)


def receive_exactly(connection, size):
    data = b""
    while len(data) < size:
        chunk = connection.recv(size - len(data))
        if not chunk:
            raise AssertionError("connection closed after %r" % data)
        data += chunk
    return data


def exception_frame(transaction, unit, function, code):
    return struct.pack(">HHHBBB", transaction, 0, 3, unit, function | 0x80, code)


class ServerMode(unittest.TestCase):
    """One run: FRAMES frames at 50 fps, then the source idles; polled by two masters."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.port = free_port()
        cls.run_ = TilthRun(
            cls.tmp.name,
            {"mode": "server", "address": "127.0.0.1", "port": cls.port,
             "stale_timeout_ms": STALE_TIMEOUT_MS},
            {"frames": FRAMES, "fps": 50, "then": "idle", "first_frame_id": FIRST_FRAME_ID,
             "invalid_every": INVALID_EVERY})
        wait_for_port(cls.port)
        # While frames arrive: blocks read by both masters, in turn.
        cls.samples = []  # (master, registers)
        deadline = time.monotonic() + 15
        while len(cls.run_.rows()) < FRAMES and time.monotonic() < deadline:
            cls.samples.append(("pymodbus", pymodbus_read(cls.port)))
            code, registers, output = mbpoll(cls.port, 0, COUNT)
            assert code == 0 and len(registers) == COUNT, output
            cls.samples.append(("mbpoll", registers))
        cls.last_frame_seen = time.monotonic()
        # After the source stopped: (seconds since the last row appeared, registers).
        cls.after = []
        while time.monotonic() - cls.last_frame_seen < 0.6:
            cls.after.append((time.monotonic() - cls.last_frame_seen, pymodbus_read(cls.port)))
            time.sleep(0.02)

    @classmethod
    def tearDownClass(cls):
        code, log = cls.run_.stop()
        cls.tmp.cleanup()
        # Checked here, after every test has connected: a clean stop and a useful log.
        assert code == 0, log
        for line in ["Modbus TCP server listening on 127.0.0.1:%d" % cls.port,
                     "Modbus client connected from 127.0.0.1:",
                     "disconnected",
                     "sent bytes that are not Modbus TCP (protocol id 21536, length 12064; "
                     "expected protocol id 0 and length 2..254); disconnected",
                     "refused function 6 from 127.0.0.1:"]:
            assert line in log, "%r not logged:\n%s" % (line, log)

    def test_blocks_read_equal_the_csv_rows_of_their_frames(self):
        rows = self.run_.rows()
        self.assertEqual(len(rows), FRAMES)
        matched = {"pymodbus": 0, "mbpoll": 0}
        frames = set()
        for master, registers in self.samples:
            values = decode(registers)
            if values["status"] & STALE:  # before the first frame
                self.assertEqual(values["status"], STALE)
                self.assertEqual(values["age"], 65535)
                self.assertEqual(values["hundredths"], 0)
                continue
            self.assertIn(values["frame"], rows, "%s read %s" % (master, registers))
            want = expected(rows[values["frame"]])
            got = {key: values[key] for key in want}
            self.assertEqual(got, want, "%s read %s" % (master, registers))
            self.assertLess(values["age"], STALE_TIMEOUT_MS)
            matched[master] += 1
            frames.add(values["frame"])
        self.assertGreaterEqual(min(matched.values()), 5, matched)
        self.assertGreater(max(frames), 0xFFFF)  # high word of the counter in use

    def test_valid_clears_and_stale_sets_after_the_source_stops(self):
        first_stale = None
        for seconds, registers in self.after:
            values = decode(registers)
            if values["status"] & STALE:
                first_stale = seconds if first_stale is None else first_stale
                # Nothing to use: no distance, no valid bit, no frames arriving.
                self.assertEqual(values["status"], STALE, registers)
                self.assertEqual((values["hundredths"], values["float_bits"]), (0, 0))
                self.assertGreater(values["age"], STALE_TIMEOUT_MS)
                self.assertEqual(values["frame"], FIRST_FRAME_ID + FRAMES - 1)
            else:
                self.assertIsNone(first_stale, "stale bit cleared again")
                self.assertLessEqual(values["age"], STALE_TIMEOUT_MS + 50)
        self.assertIsNotNone(first_stale, "never went stale")
        # Measured from when the test saw the last CSV row, at most one read late.
        self.assertLess(first_stale, (STALE_TIMEOUT_MS + 150) / 1000)

    def test_heartbeat_counts_10_ms_periods_also_while_stale(self):
        beats = [decode(registers)["heartbeat"] for _, registers in self.after]
        self.assertTrue(all(a != b for a, b in zip(beats, beats[1:])), beats)
        start = time.monotonic()
        first = decode(pymodbus_read(self.port))["heartbeat"]
        time.sleep(0.05)
        second = decode(pymodbus_read(self.port))["heartbeat"]
        elapsed_ms = (time.monotonic() - start) * 1000
        self.assertGreaterEqual((second - first) % 65536, 4)
        self.assertLessEqual((second - first) % 65536, elapsed_ms / 10 + 1)

    def test_input_registers_mirror_holding_registers_and_part_reads(self):
        client = ModbusTcpClient("127.0.0.1", port=self.port, timeout=2)
        client.connect()
        try:
            holding = client.read_holding_registers(0, COUNT, slave=1)
            inputs = client.read_input_registers(0, COUNT, slave=1)
            # Equal but for the heartbeat and age, which may have moved on.
            self.assertEqual(holding.registers[:HEARTBEAT], inputs.registers[:HEARTBEAT])
            status = client.read_holding_registers(STATUS, 1, slave=1)
            self.assertEqual(status.registers, [STALE])
        finally:
            client.close()

    def test_writes_and_out_of_range_reads_get_exceptions_pymodbus(self):
        client = ModbusTcpClient("127.0.0.1", port=self.port, timeout=2)
        client.connect()
        try:
            for result, code in [
                    (client.write_register(DISTANCE_HUNDREDTHS, 1234, slave=1), 2),
                    (client.write_registers(0, [1, 2, 3], slave=1), 2),
                    (client.read_holding_registers(5, 10, slave=1), 2),
                    (client.read_input_registers(COUNT, 1, slave=1), 2),
                    (client.read_coils(0, 1, slave=1), 1),
                    (client.write_coil(0, True, slave=1), 1)]:
                self.assertTrue(result.isError(), result)
                self.assertEqual(result.exception_code, code, result)
            # The connection is still served, and nothing was written.
            registers = client.read_holding_registers(0, COUNT, slave=1).registers
            self.assertEqual(registers[STATUS], STALE)
            self.assertEqual(registers[:2], [0, 0])
        finally:
            client.close()

    def test_exception_codes_raw(self):
        with socket.create_connection(("127.0.0.1", self.port), timeout=2) as connection:
            for transaction, unit, pdu, function, code in [
                    (1, 1, struct.pack(">BHH", 3, COUNT, 1), 3, 2),  # past the map
                    (2, 1, struct.pack(">BHH", 3, 0, COUNT + 1), 3, 2),  # runs past it
                    (3, 1, struct.pack(">BHH", 3, 0, 0), 3, 3),  # no registers
                    (4, 1, struct.pack(">BHH", 4, 0, 126), 4, 3),  # more than 125
                    (5, 1, struct.pack(">BHHB", 3, 0, 1, 0), 3, 3),  # wrong length
                    (6, 1, struct.pack(">BHH", 6, 0, 7), 6, 2),  # write: read-only
                    (7, 1, struct.pack(">BHHBH", 16, 4, 1, 2, 9), 16, 2),
                    (8, 1, struct.pack(">BH", 0x2B, 0x0E01), 0x2B, 1),  # device id: no
                    (9, 1, struct.pack(">B", 0x41), 0x41, 1),  # no such function
                    (10, 17, struct.pack(">BHH", 3, 0, 1), 3, 0x0B)]:  # another unit
                self.assertEqual(request(connection, transaction, unit, pdu),
                                 exception_frame(transaction, unit, function, code),
                                 "request %d" % transaction)
            # Units 0 and 255 address this device too; the same connection still works.
            for unit in (0, 255):
                answer = request(connection, 11, unit, struct.pack(">BHH", 3, STATUS, 1))
                self.assertEqual(answer, struct.pack(">HHHBBBH", 11, 0, 5, unit, 3, 2, STALE))

    def test_a_second_server_on_the_port_fails_to_start_naming_it(self):
        with tempfile.TemporaryDirectory() as tmp:
            second = TilthRun(tmp, {"address": "127.0.0.1", "port": self.port}, {"frames": 1})
            code, log = second.wait()
        self.assertEqual(code, 1, log)
        self.assertIn("node 'plc' (modbus.output) failed to start: cannot listen on 127.0.0.1:%d: "
                      "Address already in use" % self.port, log)

    def test_mbpoll_sees_the_exception(self):
        code, registers, output = mbpoll(self.port, COUNT, 1)
        self.assertEqual(registers, [])
        self.assertIn("Illegal data address", output)
        code, registers, output = mbpoll(self.port, STATUS, 1)
        self.assertEqual((code, registers), (0, [STALE]), output)

    def test_garbage_disconnects_only_its_sender(self):
        good = ModbusTcpClient("127.0.0.1", port=self.port, timeout=2)
        good.connect()
        try:
            self.assertFalse(good.read_holding_registers(0, COUNT, slave=1).isError())
            with socket.create_connection(("127.0.0.1", self.port), timeout=2) as garbage:
                garbage.sendall(b"GET / HTTP/1.1\r\nHost: plc\r\n\r\n")
                self.assertEqual(garbage.recv(100), b"")  # closed, no answer
            self.assertEqual(good.read_holding_registers(STATUS, 1, slave=1).registers, [STALE])
            self.assertEqual(pymodbus_read(self.port, STATUS, 1), [STALE])
        finally:
            good.close()

    def test_silent_and_half_sent_requests_block_no_one(self):
        with socket.create_connection(("127.0.0.1", self.port), timeout=2) as silent, \
                socket.create_connection(("127.0.0.1", self.port), timeout=2) as slow:
            whole = struct.pack(">HHHBBHH", 77, 0, 6, 1, 3, STATUS, 1)
            slow.sendall(whole[:5])
            start = time.monotonic()
            self.assertEqual(pymodbus_read(self.port, STATUS, 1), [STALE])
            self.assertLess(time.monotonic() - start, 0.3)
            slow.sendall(whole[5:])  # the rest, late: answered as one request
            self.assertEqual(receive_frame(slow), struct.pack(">HHHBBBH", 77, 0, 5, 1, 3, 2, STALE))
            silent.settimeout(0.05)
            with self.assertRaises(socket.timeout):
                silent.recv(1)  # still open, nothing sent to it

    def test_several_masters_at_once(self):
        failures = []

        def poll():
            client = ModbusTcpClient("127.0.0.1", port=self.port, timeout=2)
            client.connect()
            try:
                for _ in range(20):
                    result = client.read_holding_registers(0, COUNT, slave=1)
                    if result.isError() or result.registers[STATUS] != STALE:
                        failures.append(result)
            finally:
                client.close()

        threads = [threading.Thread(target=poll) for _ in range(4)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        self.assertEqual(failures, [])


PLC_HOST = "127.0.0.2"  # the loopback network is 127.0.0.0/8: a PLC of its own address
OUTSIDER_HOST = "127.0.0.3"
IDLE_TIMEOUT_MS = 1000
POLICY_FIRST_FRAME = 1000


def sequence_distance(frame):
    """The distance testdistance.sequence gives `frame` (start 518.23, step 0.37 mm),
    rounded to 0.01 mm as it does (half away from zero)."""
    return math.floor((518.23 + 0.37 * (frame - POLICY_FIRST_FRAME)) * 100.0 + 0.5) / 100.0


def connect_from(host, port):
    return socket.create_connection(("127.0.0.1", port), timeout=2, source_address=(host, 0))


def closed_within(connection, seconds):
    """How long until the server closed `connection` (sending nothing), or None."""
    start = time.monotonic()
    connection.settimeout(seconds)
    try:
        data = connection.recv(1)
    except socket.timeout:
        return None
    except ConnectionResetError:  # closed with what the client sent still unread
        return time.monotonic() - start
    if data != b"":
        raise AssertionError("the server sent %r instead of closing" % data)
    return time.monotonic() - start


def read_block(connection, transaction=1):
    return request(connection, transaction, 1, struct.pack(">BHH", 3, 0, COUNT))


class PlcPoller(threading.Thread):
    """The PLC: pymodbus from PLC_HOST reading the block every 20 ms until stopped; keeps
    every poll's (latency s, registers or error, local address of its connection)."""

    def __init__(self, port):
        super().__init__()
        self.client = ModbusTcpClient("127.0.0.1", port=port, timeout=1,
                                      source_address=(PLC_HOST, 0))
        self.polls = []
        self.stopping = threading.Event()

    def run(self):
        self.client.connect()
        next_poll = time.monotonic()
        while not self.stopping.is_set():
            start = time.monotonic()
            try:
                result = self.client.read_holding_registers(0, COUNT, slave=1)
                outcome = result if result.isError() else list(result.registers)
            except Exception as error:  # pylint: disable=broad-except
                outcome = error
            local = self.client.socket.getsockname() if self.client.socket else None
            self.polls.append((time.monotonic() - start, outcome, local))
            next_poll += 0.02
            self.stopping.wait(max(0.0, next_poll - time.monotonic()))
        self.client.close()

    def stop(self):
        self.stopping.set()
        self.join(timeout=10)


class Connections(unittest.TestCase):
    """Server mode with a PLC at PLC_HOST, `allow` = 127.0.0.1, idle timeout 1 s: each test
    with a run of its own, an endless sequence at 50 fps."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.port = free_port()
        self.run_ = TilthRun(
            self.tmp.name,
            {"mode": "server", "address": "127.0.0.1", "port": self.port,
             "plc_address": PLC_HOST, "allow": ["127.0.0.1/32"], "max_clients": 8,
             "idle_timeout_ms": IDLE_TIMEOUT_MS},
            {"frames": 0, "fps": 50, "first_frame_id": POLICY_FIRST_FRAME})
        wait_for_port(self.port)
        deadline = time.monotonic() + 10
        while decode(pymodbus_read(self.port))["status"] & STALE:  # until the first frame
            self.assertLess(time.monotonic(), deadline, "no measurement arrives")
            time.sleep(0.02)

    def tearDown(self):
        code, log = self.run_.stop()
        self.tmp.cleanup()
        self.assertEqual(code, 0, log)

    def stop(self):
        """Stops the run before the test ends; returns what it logged."""
        code, log = self.run_.stop()
        self.assertEqual(code, 0, log)
        return log

    def assert_the_right_distance(self, registers):
        values = decode(registers)
        distance = sequence_distance(values["frame"])
        self.assertEqual(values["status"] & (VALID | STALE), VALID, registers)
        self.assertEqual(values["hundredths"], round(distance * 100), registers)
        self.assertEqual(values["float_bits"],
                         struct.unpack(">I", struct.pack(">f", distance))[0], registers)
        self.assertEqual(values["soil"], (values["frame"] - POLICY_FIRST_FRAME) % 97 * 100 + 12)
        self.assertLess(values["age"], STALE_TIMEOUT_MS)
        return values["frame"]

    def test_the_plc_is_served_through_a_crowd(self):
        seconds = 8
        plc = PlcPoller(self.port)
        plc.start()
        time.sleep(0.2)
        # One idle client surely inside before the crowd fills max_clients: the crowd's
        # own idle bursts may all be turned away when a loaded machine lets pollers in first.
        idle = connect_from("127.0.0.1", self.port)
        crowd_output = os.path.join(self.tmp.name, "crowd.txt")
        with idle, open(crowd_output, "w") as output:
            crowd = subprocess.Popen([sys.executable, CROWD, str(self.port), str(seconds)],
                                     stdout=output, stderr=subprocess.STDOUT)
            try:
                crowd.wait(timeout=seconds + 20)
            finally:
                if crowd.poll() is None:
                    crowd.kill()
                    crowd.wait()
        time.sleep(0.2)
        plc.stop()
        log = self.stop()
        with open(crowd_output) as output:
            crowd_text = output.read(10000)
        counts = json.loads(crowd_text.splitlines()[-1])

        # The crowd was really there: some of its pollers served, many turned away.
        self.assertGreater(counts["answered"], 100, crowd_text)
        self.assertGreater(counts["closed"] + counts["failed"], 100, crowd_text)
        # Every poll of the PLC answered, on one connection, with the sequence's distance.
        self.assertGreaterEqual(len(plc.polls), seconds * 50 * 0.7)
        self.assertEqual([outcome for _, outcome, _ in plc.polls if not isinstance(outcome, list)],
                         [])
        connections = {local for _, _, local in plc.polls}
        self.assertEqual(len(connections), 1, connections)
        frames = [self.assert_the_right_distance(registers) for _, registers, _ in plc.polls]
        self.assertEqual(frames, sorted(frames))
        self.assertGreater(frames[-1] - frames[0], seconds * 50 * 0.7)
        latencies = sorted(latency for latency, _, _ in plc.polls)
        print("\nPLC polls: %d, latency median %.1f ms, 99th %.1f ms, max %.1f ms; crowd %s"
              % (len(latencies), latencies[len(latencies) // 2] * 1000,
                 latencies[len(latencies) * 99 // 100] * 1000, latencies[-1] * 1000,
                 counts), file=sys.stderr)
        self.assertLess(latencies[-1], 0.5)  # far inside the PLC's 1 s timeout
        # Connected, and disconnected only when the PLC itself left after the crowd.
        plc_lines = [line for line in log.splitlines()
                     if "Modbus client" in line and PLC_HOST in line]
        self.assertEqual(len(plc_lines), 2, plc_lines)
        self.assertRegex(plc_lines[0], r"Modbus client connected from 127\.0\.0\.2:\d+ \(PLC\)$")
        self.assertRegex(plc_lines[1], r"Modbus client 127\.0\.0\.2:\d+ \(PLC\) disconnected$")
        # Each kind of flood is one line, then one summing up the rest (here when the run
        # stops, before 10 s are over): refusals of outsiders and when full, idle closes,
        # protocol errors, comings and goings; plus the run's own lines.
        for what in [r"refused the connection from 127\.0\.0\.3:\d+: not in 'allow'",
                     r"refused the connection from 127\.0\.0\.1:\d+: max_clients \(8\)",
                     r"\d\d+ more like it in the last \d s; the latest: refused the connection "
                     r"from 127\.0\.0\.3",
                     r"\d{3,} more like it in the last \d s; the latest: refused the connection "
                     r"from 127\.0\.0\.1",
                     r"closed: no request for 1\d\d\d ms", "sent bytes that are not Modbus TCP",
                     "Modbus client connected from 127.0.0.1:"]:
            self.assertRegex(log, what)
        self.assertLess(len(log.splitlines()), 30, log)

    def test_idle_clients_are_closed_after_the_timeout_not_the_plc(self):
        timeout = IDLE_TIMEOUT_MS / 1000
        start = time.monotonic()  # the server accepts each connection after this
        with connect_from("127.0.0.1", self.port) as silent, \
                connect_from("127.0.0.1", self.port) as quiet, \
                connect_from("127.0.0.1", self.port) as slow, \
                connect_from(PLC_HOST, self.port) as plc:
            slow.sendall(b"\0")  # a request's first bytes, one at a time
            time.sleep(0.5)
            self.assert_the_right_distance(list(struct.unpack(">%dH" % COUNT, read_block(quiet)[9:])))
            for _ in range(3):
                time.sleep(0.1)
                slow.sendall(b"\0")
            silent_closed = time.monotonic() - start + closed_within(silent, 2)
            slow_closed = time.monotonic() - start + closed_within(slow, 2)
            quiet_closed = time.monotonic() - start + closed_within(quiet, 2)
            # Not before the timeout; afterwards within one poll wake-up and scheduling.
            self.assertGreaterEqual(silent_closed, timeout)
            self.assertLess(silent_closed, timeout + 0.3)
            self.assertGreaterEqual(slow_closed, timeout)  # bytes are not requests
            self.assertLess(slow_closed, timeout + 0.3)
            self.assertGreaterEqual(quiet_closed, 0.5 + timeout)  # from its request
            self.assertLess(quiet_closed, 0.5 + timeout + 0.3)
            # The PLC's silent connection stays, and is served.
            self.assertIsNone(closed_within(plc, 0.6))
            self.assertGreater(time.monotonic() - start, 2 * timeout)
            plc.settimeout(2)
            self.assert_the_right_distance(list(struct.unpack(">%dH" % COUNT, read_block(plc)[9:])))
        log = self.stop()
        self.assertRegex(log, r"Modbus client 127\.0\.0\.1:\d+ closed: no request for 1\d\d\d ms "
                              r"\(idle_timeout_ms 1000\)")

    def test_an_address_outside_allow_is_closed_at_once(self):
        with connect_from(OUTSIDER_HOST, self.port) as outsider:
            outsider.sendall(struct.pack(">HHHBBHH", 1, 0, 6, 1, 3, 0, COUNT))
            self.assertLess(closed_within(outsider, 1), 0.2)
        with connect_from("127.0.0.1", self.port) as allowed:
            self.assert_the_right_distance(list(struct.unpack(">%dH" % COUNT, read_block(allowed)[9:])))
        log = self.stop()
        self.assertRegex(log, r"refused the connection from 127\.0\.0\.3:\d+: not in 'allow' "
                              r"\(127\.0\.0\.1\)")

    def test_beyond_max_clients_a_newcomer_is_refused_and_no_one_evicted(self):
        others = [connect_from("127.0.0.1", self.port) for _ in range(8)]
        try:
            for transaction, connection in enumerate(others):
                read_block(connection, transaction)  # all eight active
            with connect_from("127.0.0.1", self.port) as ninth:
                self.assertLess(closed_within(ninth, 1), 0.2)
            # Room for the PLC all the same, and the eight are still served.
            with connect_from(PLC_HOST, self.port) as plc:
                self.assert_the_right_distance(list(struct.unpack(">%dH" % COUNT, read_block(plc)[9:])))
            for transaction, connection in enumerate(others):
                registers = struct.unpack(">%dH" % COUNT, read_block(connection, transaction)[9:])
                self.assert_the_right_distance(list(registers))
        finally:
            for connection in others:
                connection.close()
        log = self.stop()
        self.assertRegex(log, r"refused the connection from 127\.0\.0\.1:\d+: max_clients \(8\) "
                              r"other clients are connected")
        self.assertNotIn("closing the one", log)

    def test_malformed_frames_close_only_their_sender(self):
        plc = PlcPoller(self.port)
        plc.start()
        time.sleep(0.2)
        try:
            for garbage in [struct.pack(">HHHBBHH", 1, 1, 6, 1, 3, 0, COUNT),  # protocol 1
                            struct.pack(">HHHB", 1, 0, 0, 1),  # length 0
                            struct.pack(">HHHBB", 1, 0, 1, 1, 3),  # length 1: no function
                            struct.pack(">HHHB", 1, 0, 255, 1),  # one past the largest
                            struct.pack(">HHHB", 1, 0, 0xFFFF, 1) + b"\0" * 100,
                            struct.pack(">HHHBBB", 1, 0, 3, 1, 0x83, 2)]:  # a response
                with connect_from("127.0.0.1", self.port) as sender:
                    sender.sendall(garbage)
                    self.assertLess(closed_within(sender, 1), 0.2, garbage)
            with connect_from("127.0.0.1", self.port) as sender:
                # The largest frame there is, but not a read: an exception, still connected;
                # then two requests in one segment: two answers.
                sender.sendall(struct.pack(">HHHBB", 5, 0, 254, 1, 3) + b"\0" * 252)
                self.assertEqual(receive_frame(sender), exception_frame(5, 1, 3, 3))
                read = struct.pack(">HHHBBHH", 6, 0, 6, 1, 3, STATUS, 1)
                sender.sendall(read + read.replace(b"\0\6\0\0", b"\0\7\0\0", 1))
                for transaction in (6, 7):
                    self.assertEqual(receive_frame(sender)[:9],
                                     struct.pack(">HHHBBB", transaction, 0, 5, 1, 3, 2))
            time.sleep(0.2)
        finally:
            plc.stop()
        log = self.stop()
        self.assertGreater(len(plc.polls), 5)
        self.assertEqual(len({local for _, _, local in plc.polls}), 1)
        for _, registers, _ in plc.polls:
            self.assert_the_right_distance(registers)
        self.assertIn("sent bytes that are not Modbus TCP (protocol id 1, length 6; expected "
                      "protocol id 0 and length 2..254); disconnected", log)
        self.assertRegex(log, r"5 more like it in the last \d+ s; the latest: Modbus client "
                              r"127\.0\.0\.1:\d+ sent function code 131, which is not a request")

    def test_a_reconnecting_plc_replaces_its_own_quietest_connection(self):
        with connect_from(PLC_HOST, self.port) as dead, \
                connect_from(PLC_HOST, self.port) as polling:
            time.sleep(0.1)
            read_block(polling)
            with connect_from(PLC_HOST, self.port) as again:  # plc_clients is 2
                self.assertLess(closed_within(dead, 1), 0.2)
                self.assert_the_right_distance(list(struct.unpack(">%dH" % COUNT, read_block(again)[9:])))
                self.assert_the_right_distance(
                    list(struct.unpack(">%dH" % COUNT, read_block(polling)[9:])))
            dead_port = dead.getsockname()[1]
        log = self.stop()
        self.assertRegex(log, r"plc_clients \(2\) PLC connections open: closing the one from "
                              r"127\.0\.0\.2:%d, quiet for \d+ ms, to accept 127\.0\.0\.2:\d+"
                              % dead_port)

    def test_a_wrong_plc_address_fails_to_start_naming_it(self):
        with tempfile.TemporaryDirectory() as tmp:
            wrong = TilthRun(tmp, {"address": "127.0.0.1", "port": free_port(),
                                   "plc_address": ["192.168.1.10", "192.168.1.0/33"]},
                             {"frames": 1})
            code, log = wrong.wait()
        self.assertEqual(code, 1, log)
        self.assertIn("node 'plc' (modbus.output) failed to start: parameter 'plc_address'/1: "
                      "expected an IPv4 address such as 192.168.1.10 or a CIDR block such as "
                      "192.168.1.0/24 (prefix length 0..32), got '192.168.1.0/33'", log)


class ClientMode(unittest.TestCase):
    """Tilth writes into a stand-in PLC that comes up late and restarts."""

    BASE = 100  # registers 100..111, low word first

    def start_plc(self):
        plc = subprocess.Popen([sys.executable, PLC_SERVER, str(self.port)],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wait_for_port(self.port)
        return plc

    def read_plc(self):
        registers = pymodbus_read(self.port, self.BASE, COUNT)
        return decode(registers, "little")

    def wait_for_writes(self, timeout):
        """The PLC's block once Tilth has written it (heartbeat and frame set)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            values = self.read_plc()
            if values["frame"] != 0:
                return values
            time.sleep(0.02)
        self.fail("no writes arrived within %.1f s" % timeout)

    def check_against_csv(self, run):
        for _ in range(5):
            values = self.read_plc()
            time.sleep(0.05)  # the CSV row of that frame is written by now
            rows = run.rows()
            self.assertIn(values["frame"], rows)
            want = expected(rows[values["frame"]])
            self.assertEqual({key: values[key] for key in want}, want)

    def test_writes_reach_the_plc_and_resume_after_it_restarts(self):
        self.port = free_port()
        with tempfile.TemporaryDirectory() as tmp:
            run = TilthRun(
                tmp,
                {"mode": "client", "address": "127.0.0.1", "port": self.port, "unit_id": 1,
                 "base_register": self.BASE, "word_order": "little", "write_interval_ms": 20},
                {"frames": 0, "fps": 50, "first_frame_id": 1000, "invalid_every": INVALID_EVERY})
            plc = None
            try:
                run.wait_running()
                time.sleep(0.3)  # Tilth runs before the PLC is up
                plc = self.start_plc()
                first = self.wait_for_writes(timeout=4)
                self.check_against_csv(run)
                # About one heartbeat per write (20 ms).
                time.sleep(0.2)
                beats = (self.read_plc()["heartbeat"] - first["heartbeat"]) % 65536
                self.assertGreaterEqual(beats, 5)

                plc.kill()
                plc.wait()
                time.sleep(0.5)
                plc = self.start_plc()  # registers all 0 again
                again = self.wait_for_writes(timeout=4)
                self.assertGreater(again["frame"], first["frame"])
                self.check_against_csv(run)
            finally:
                code, log = run.stop()
                if plc is not None:
                    plc.kill()
                    plc.wait()
            self.assertEqual(code, 0, log)
            where = "127.0.0.1:%d" % self.port
            self.assertIn("cannot connect to the PLC at %s: Connection refused; retrying" % where,
                          log)
            self.assertEqual(log.count("connected to the PLC at %s; writing registers 100..111"
                                       % where), 2, log)
            self.assertIn("connection to the PLC at %s lost" % where, log)

    def test_a_refused_write_keeps_the_connection(self):
        self.port = free_port()
        plc = self.start_plc()  # registers 0..199: a block from 195 does not fit
        try:
            with tempfile.TemporaryDirectory() as tmp:
                run = TilthRun(
                    tmp, {"mode": "client", "address": "127.0.0.1", "port": self.port,
                          "base_register": 195, "write_interval_ms": 20},
                    {"frames": 0, "fps": 50})
                run.wait_running()
                time.sleep(0.5)
                code, log = run.stop()
        finally:
            plc.kill()
            plc.wait()
        self.assertEqual(code, 0, log)
        where = "127.0.0.1:%d" % self.port
        self.assertEqual(log.count("the PLC at %s refused the write to registers 195..206: "
                                   "Illegal data address; writing on" % where), 1, log)
        self.assertEqual(log.count("connected to the PLC at %s" % where), 1, log)
        self.assertNotIn("lost", log)


if __name__ == "__main__":
    unittest.main()
