#!/usr/bin/env python3
# An RCB-4 stand-in written here in Python from protocol.md, independent of this project's code:
# a board that is not ours, for the CLI's tests and the transport bench. As a program it serves
# one on a pseudo-terminal, prints the path, and serves until killed:
#   python3 tests/integration/standin.py [--mode nack|badsum|echo|drop|short|empty|late|die|cut]
# SPDX-License-Identifier: BSL-1.0
import os
import socket
import threading
import time
import tty


class StandIn:
    """A minimal RCB-4 on a pty (protocol.md §2, §4): ping, VERSION, MOV RAM->COM, MOV literal->RAM,
    SINGLE/CONST servo (ACK). Records every frame it receives. silent=True answers nothing;
    mode "nack" answers every frame with NACK, "badsum" spoils every reply's checksum, "echo"
    sends every byte back (a loopback plug), "drop" leaves every third frame unanswered,
    "short" answers data requests with a frame one byte shorter (a wrong length), "cut" sends every
    reply without its last byte, "empty" has an
    allocation table of zeros (a board nobody set up), "late" answers 300 ms late, "die" stops
    answering after `die_after` frames (a board that loses power mid-transfer)."""

    def __init__(self, silent=False, mode=None, die_after=20, tcp=False, pace_baud=0, latency_us=0):
        self.mode = mode
        self.pace_baud, self.latency_us = pace_baud, latency_us  # reply no sooner than the wire would
        self.die_after = die_after
        self.ram = bytearray(0x490)
        self.ram[0:2] = bytes([0x8B, 0x00])  # config word 0x008B
        for k in range(36):  # allocation table at 0x0044: ICS 0-2 allocated at 0x0090 + 20k
            a = 0x0090 + 20 * k if k < 3 else 0xFFFF
            if mode == "empty":
                a = 0
            if k < 35:
                self.ram[0x44 + 2 * k:0x46 + 2 * k] = a.to_bytes(2, "little")
        for k in range(3):
            self.ram[0x90 + 20 * k + 4:0x90 + 20 * k + 8] = (7500).to_bytes(2, "little") * 2
        self.frames = []
        self.silent = silent
        if tcp:  # tcp=True: one client on a loopback port (path is HOST:PORT), as ser2net would
            self.listener = socket.create_server(("127.0.0.1", 0))
            self.path = "127.0.0.1:%d" % self.listener.getsockname()[1]
            threading.Thread(target=self.accept, daemon=True).start()
            return
        self.master, slave = os.openpty()
        tty.setraw(slave)
        self.path = os.ttyname(slave)
        self.slave = slave
        threading.Thread(target=self.serve, daemon=True).start()

    def accept(self):
        self.conn, _ = self.listener.accept()
        self.master = self.conn.fileno()
        self.serve()

    def reply(self, b):
        if self.mode == "nack":
            b = [0x04, b[1], 0x15]
        if self.mode == "short" and b[0] > 4:
            b = [b[0] - 1] + b[1:-1]  # a whole frame, one data byte shorter than the request asked for
        total = (sum(b) + (0x5A if self.mode == "badsum" else 0)) & 0xFF
        if self.mode == "late":
            time.sleep(0.3)
        if self.pace_baud or self.latency_us:  # the reply's bytes at 11 bits each, after the adapter's latency
            time.sleep((len(b) + 1) * 11 / (self.pace_baud or 1e12) + self.latency_us / 1e6)
        if self.mode == "cut":  # the reply stops one byte short (a line that fails mid-reply)
            os.write(self.master, bytes(b))
            return
        os.write(self.master, bytes(b) + bytes([total]))

    def serve(self):
        buf = b""
        while True:
            try:
                got = os.read(self.master, 512)
            except OSError:
                return
            if not got:  # a TCP client that closed
                return
            if self.mode == "echo":
                os.write(self.master, got)
                continue
            buf += got
            while buf and len(buf) >= buf[0] >= 3:
                f, buf = buf[:buf[0]], buf[buf[0]:]
                self.count = getattr(self, "count", 0) + 1
                if self.frames is not None:
                    self.frames.append(f)
                if self.silent or sum(f[:-1]) & 0xFF != f[-1]:
                    continue
                if self.mode == "drop" and self.count % 3 == 0:
                    continue
                if self.mode == "die" and self.count > self.die_after:
                    continue
                cmd = f[1]
                if cmd == 0xFE:
                    self.reply([0x04, 0xFE, 0x06])
                elif cmd == 0xFD:
                    self.reply([0x23, 0xFD] + list(b"STAND-IN RCB-4 (python)".ljust(32)))
                elif cmd == 0x00 and f[2] == 0x20 and len(f) == 10:  # RAM -> COM
                    a, n = f[6] | f[7] << 8, f[8]
                    self.reply([n + 3, 0x00] + list(self.ram[a:a + n]))
                elif cmd == 0x00 and f[2] == 0x23 and len(f) == 11:  # ROM -> COM: an erased ROM
                    n = f[9]
                    self.reply([n + 3, 0x00] + [0xFF] * n)
                elif cmd == 0x00 and f[2] == 0x32:  # literal -> ROM (acknowledged, not kept)
                    self.reply([0x04, 0x00, 0x06])
                elif cmd == 0x00 and f[2] == 0x02:  # literal -> RAM
                    a = f[3] | f[4] << 8
                    self.ram[a:a + len(f) - 7] = f[6:-1]
                    self.reply([0x04, 0x00, 0x06])
                elif cmd in (0x0F, 0x10, 0x12):
                    self.reply([0x04, cmd, 0x06])
                else:
                    self.reply([0x04, cmd, 0x15])


if __name__ == "__main__":
    import argparse
    ap = argparse.ArgumentParser(description="an RCB-4 stand-in on a pty")
    ap.add_argument("--mode", choices=["nack", "badsum", "echo", "drop", "short", "empty", "late", "die", "cut"])
    a = ap.parse_args()
    board = StandIn(mode=a.mode)
    board.frames = None  # (a long run keeps no log)
    print(board.path, flush=True)
    try:
        threading.Event().wait()  # until Ctrl-C (SIGINT) or SIGTERM
    except KeyboardInterrupt:
        pass
