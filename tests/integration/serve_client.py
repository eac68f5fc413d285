#!/usr/bin/env python3
"""A client in another process and language drives `rcb4 serve` over a pty and over TCP.

Every request is written by hand as other RCB-4 libraries put it on the wire (protocol.md
§4, §8.1); every expected reply is written by hand too. Usage: serve_client.py PATH/TO/rcb4
"""
import os
import select
import signal
import socket
import subprocess
import sys
import tempfile
import termios
import time

RCB4 = sys.argv[1]
from checks import check, finish


def frame(*b):
    """A hand-written frame; the assertion double-checks the hand-computed SIZE and SUM."""
    b = bytes(b)
    assert b[0] == len(b) and sum(b[:-1]) & 0xFF == b[-1], b.hex(" ")
    return b


class Serve:
    def __init__(self, *args):
        self.proc = subprocess.Popen([RCB4, "serve", *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.where = self.proc.stdout.readline().strip()

    def stop(self):
        self.proc.send_signal(signal.SIGINT)
        return self.proc.wait(timeout=5)


class PtyLine:
    def __init__(self, path):
        self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
        a = termios.tcgetattr(self.fd)
        a[0] = a[1] = a[3] = 0
        a[2] = termios.CS8 | termios.PARENB | termios.CLOCAL | termios.CREAD
        a[4] = a[5] = termios.B115200
        termios.tcsetattr(self.fd, termios.TCSANOW, a)

    def write(self, b):
        os.write(self.fd, b)

    def read(self, n, timeout=1.0):
        out, end = b"", time.time() + timeout
        while len(out) < n and time.time() < end:
            r, _, _ = select.select([self.fd], [], [], max(0.0, end - time.time()))
            if r:
                out += os.read(self.fd, 512)
        return out

    def close(self):
        os.close(self.fd)


class TcpLine:
    def __init__(self, where):
        host, port = where.rsplit(":", 1)
        self.s = socket.create_connection((host, int(port)), timeout=2)
        self.s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)

    def write(self, b):
        self.s.sendall(b)

    def read(self, n, timeout=1.0):
        out, end = b"", time.time() + timeout
        while len(out) < n and time.time() < end:
            self.s.settimeout(max(0.01, end - time.time()))
            try:
                chunk = self.s.recv(512)
            except socket.timeout:
                break
            if not chunk:
                break
            out += chunk
        return out

    def close(self):
        self.s.close()


def xfer(line, request, n):
    line.write(request)
    return line.read(n)


PING = frame(0x04, 0xFE, 0x06, 0x08)
ACK_PING = bytes([0x04, 0xFE, 0x06, 0x08])


def exercise(line, label):
    check(xfer(line, PING, 4) == ACK_PING, f"{label}: ping (04 FE 06 08) is ACKed")
    check(xfer(line, frame(0x03, 0xFE, 0x01), 4) == ACK_PING, f"{label}: short ping (03 FE 01) is ACKed")
    # getConfig as KONDO's Python library sends it: MOV RAM 0x0000, 2 bytes → COM.
    check(xfer(line, frame(0x0A, 0x00, 0x20, 0x00, 0x00, 0x00, 0x00, 0x00, 0x02, 0x2C), 5)
          == bytes([0x05, 0x00, 0x8B, 0x00, 0x90]), f"{label}: config word reads 0x008B")
    v = xfer(line, frame(0x03, 0xFD, 0x00), 35)
    check(len(v) == 35 and v[1:-1] == b"\xfd" + b"CB-4 V1.0      090715          " + b"\xc7",
          f"{label}: VERSION is what an RCB-4mini client checks for")
    # SINGLE ICS 0 → 7500 in 10 frames, then CONST ICS 1 → 7500, ICS 3 → 8000 in 20 frames.
    check(xfer(line, frame(0x07, 0x0F, 0x00, 0x0A, 0x4C, 0x1D, 0x89), 4) == bytes([0x04, 0x0F, 0x06, 0x19]),
          f"{label}: SINGLE is ACKed")
    check(xfer(line, frame(0x0D, 0x10, 0x0A, 0x00, 0x00, 0x00, 0x00, 0x14, 0x4C, 0x1D, 0x40, 0x1F, 0x03), 4)
          == bytes([0x04, 0x10, 0x06, 0x1A]), f"{label}: CONST is ACKed")
    time.sleep(0.35)
    # ICS 3 current position (ICS → COM, +4, 2 bytes): 8000 = 40 1F.
    check(xfer(line, frame(0x0A, 0x00, 0x21, 0x00, 0x00, 0x00, 0x04, 0x03, 0x02, 0x34), 5)
          == bytes([0x05, 0x00, 0x40, 0x1F, 0x64]), f"{label}: ICS 3 reached 8000")
    # Bad checksum → NACK.
    check(xfer(line, bytes([0x04, 0xFE, 0x06, 0x09]), 4) == bytes([0x04, 0xFE, 0x15, 0x17]),
          f"{label}: a bad checksum is NACKed")
    # Unallocated slot ICS 30 → NACK.
    check(xfer(line, frame(0x07, 0x0F, 0x1E, 0x0A, 0x4C, 0x1D, 0xA7), 4) == bytes([0x04, 0x0F, 0x15, 0x28]),
          f"{label}: SINGLE on an unallocated slot is NACKed")


def motion_play(line, label):
    # KONDO's four steps for motion 2 (HTH4 2.2: 0x000B80 + 2048 = 0x001380), protocol.md §8.1.
    steps = [
        frame(0x09, 0x00, 0x02, 0x00, 0x00, 0x00, 0x80, 0x00, 0x8B),  # suspend: config 0x0080
        frame(0x11, 0x00, 0x02, 0x02, 0x00, 0x00, 0x4B, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x64),
        frame(0x07, 0x0C, 0x80, 0x13, 0x00, 0x00, 0xA6),  # CALL 0x001380
        frame(0x09, 0x00, 0x02, 0x00, 0x00, 0x00, 0x8B, 0x00, 0x96),  # resume: config 0x008B
    ]
    acks = [xfer(line, s, 4) for s in steps]
    check([a[2] if len(a) == 4 else None for a in acks] == [0x06] * 4, f"{label}: the four motion-play steps are ACKed")
    status = frame(0x0A, 0x00, 0x20, 0x00, 0x00, 0x00, 0x02, 0x00, 0x0A, 0x36)  # 10 bytes at 0x0002

    def running():
        r = xfer(line, status, 13)
        return len(r) == 13 and sum(r[5:10]) != 0

    check(running(), f"{label}: status says a motion runs")
    read_ics5 = frame(0x0A, 0x00, 0x21, 0x00, 0x00, 0x00, 0x04, 0x05, 0x02, 0x36)
    seen = set()
    end = time.time() + 3
    while time.time() < end and running():
        r = xfer(line, read_ics5, 5)
        if len(r) == 5:
            seen.add(r[2] | (r[3] << 8))
        time.sleep(0.01)
    check(not running(), f"{label}: the motion ends and the program is back in its main loop")
    check(10500 in seen or max(seen, default=0) > 9000, f"{label}: the right arm moved (saw {sorted(seen)[-3:]})")


def main():
    s = Serve("--pty")
    check(s.where.startswith("/dev/pts/"), f"serve --pty prints the device first ({s.where})")
    line = PtyLine(s.where)
    exercise(line, "pty")
    motion_play(line, "pty")
    line.close()
    check(s.stop() == 0, "serve --pty stops on SIGINT with status 0")

    s = Serve("--tcp", "127.0.0.1:0", "--pace", "--latency", "200")
    check(s.where.startswith("127.0.0.1:"), f"serve --tcp prints HOST:PORT first ({s.where})")
    line = TcpLine(s.where)
    exercise(line, "tcp")
    t = time.perf_counter()
    for _ in range(50):
        xfer(line, PING, 4)
    per = (time.perf_counter() - t) / 50
    # 200 µs latency + 8 bytes at 1.25 Mbaud (70 µs): each round trip takes at least that.
    check(per >= 270e-6, f"tcp: --pace --latency 200 slows a ping round trip to {per * 1e6:.0f} us (>= 270)")
    line.close()
    check(s.stop() == 0, "serve --tcp stops on SIGINT with status 0")

    with tempfile.TemporaryDirectory() as d:
        rom = os.path.join(d, "robot.rom")
        s = Serve("--pty", "--rom", rom)
        line = PtyLine(s.where)
        check(xfer(line, frame(0x09, 0x00, 0x32, 0x00, 0x10, 0x00, 0xAA, 0x55, 0x4A), 4) == bytes([0x04, 0x00, 0x06, 0x0A]),
              "rom: literal → ROM 0x001000 is ACKed")
        line.close()
        s.stop()
        check(os.path.getsize(rom) == 262144, "rom: the image is saved on exit (256 KiB)")
        s = Serve("--pty", "--rom", rom)
        line = PtyLine(s.where)
        check(xfer(line, frame(0x0B, 0x00, 0x23, 0x00, 0x00, 0x00, 0x00, 0x10, 0x00, 0x02, 0x40), 5)
              == bytes([0x05, 0x00, 0xAA, 0x55, 0x04]), "rom: a restarted board still has the bytes")
        line.close()
        s.stop()

    bad = subprocess.run([RCB4, "serve", "--tcp", "nowhere:1"], capture_output=True, text=True)
    check(bad.returncode == 2 and "not an IP address" in bad.stderr, "serve: a bad --tcp address is a usage error")
    bad = subprocess.run([RCB4, "serve"], capture_output=True, text=True)
    check(bad.returncode == 2 and "--pty or --tcp" in bad.stderr, "serve: no transport named is a usage error")

    finish()


main()
