# A small WebSocket client (RFC 6455) on a plain socket, for testing `rcb4 ui` the way a hostile
# or careless client would: any Origin, any bytes, a connection dropped without a close.
# SPDX-License-Identifier: BSL-1.0
import base64
import json
import os
import socket
import struct
import time


def http_get(port, path, headers=None, host=None):
    """One HTTP/1.1 GET; returns (status, headers dict lower-case, body bytes)."""
    s = socket.create_connection(("127.0.0.1", port), timeout=10)
    h = {"Host": host or f"127.0.0.1:{port}", "Connection": "close", **(headers or {})}
    s.sendall((f"GET {path} HTTP/1.1\r\n" + "".join(f"{k}: {v}\r\n" for k, v in h.items()) + "\r\n").encode())
    data = b""
    while True:
        chunk = s.recv(65536)
        if not chunk:
            break
        data += chunk
    s.close()
    head, _, body = data.partition(b"\r\n\r\n")
    lines = head.decode("latin-1").split("\r\n")
    status = int(lines[0].split()[1])
    fields = {}
    for line in lines[1:]:
        k, _, v = line.partition(":")
        fields[k.strip().lower()] = v.strip()
    return status, fields, body


class WebSocket:
    """A client WebSocket to 127.0.0.1:port/ws; `status` is the handshake's HTTP status."""

    def __init__(self, port, origin=None, path="/ws", host=None):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=10)
        key = base64.b64encode(os.urandom(16)).decode()
        h = {"Host": host or f"127.0.0.1:{port}", "Upgrade": "websocket", "Connection": "Upgrade",
             "Sec-WebSocket-Key": key, "Sec-WebSocket-Version": "13"}
        if origin is not None:
            h["Origin"] = origin
        self.sock.sendall((f"GET {path} HTTP/1.1\r\n" + "".join(f"{k}: {v}\r\n" for k, v in h.items()) + "\r\n").encode())
        head = b""
        while b"\r\n\r\n" not in head:
            chunk = self.sock.recv(1)
            if not chunk:
                break
            head += chunk
        self.status = int(head.split(b" ")[1]) if head else 0
        self.buf = b""

    def send_text(self, text, opcode=1):
        data = text.encode() if isinstance(text, str) else text
        mask = os.urandom(4)
        n = len(data)
        header = bytes([0x80 | opcode])
        if n < 126:
            header += bytes([0x80 | n])
        elif n < 65536:
            header += bytes([0x80 | 126]) + struct.pack(">H", n)
        else:
            header += bytes([0x80 | 127]) + struct.pack(">Q", n)
        self.sock.sendall(header + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))

    def send(self, obj):
        self.send_text(json.dumps(obj))

    def _read(self, n):
        while len(self.buf) < n:
            chunk = self.sock.recv(65536)
            if not chunk:
                raise ConnectionError("closed")
            self.buf += chunk
        out, self.buf = self.buf[:n], self.buf[n:]
        return out

    def recv(self, timeout=5):
        """The next text message as an object (pings answered); None when the server closed."""
        self.sock.settimeout(timeout)
        parts = []  # a message the server sent in fragments (text, then continuations until FIN)
        while True:
            try:
                b0, b1 = self._read(2)
            except ConnectionError:
                return None
            n = b1 & 0x7F
            if n == 126:
                n = struct.unpack(">H", self._read(2))[0]
            elif n == 127:
                n = struct.unpack(">Q", self._read(8))[0]
            payload = self._read(n)
            op = b0 & 0x0F
            if op == 8:  # answer the close, as a browser does
                try:
                    code = payload[:2]
                    self.sock.sendall(bytes([0x88, 0x80 | len(code)]) + b"\0\0\0\0" + code)
                except OSError:
                    pass
                return None
            if op == 9:
                self.send_text(payload, opcode=10)
                continue
            if op in (0, 1):
                parts.append(payload)
                if b0 & 0x80:  # FIN: the message is whole
                    return json.loads(b"".join(parts))

    def wait_for(self, pred, timeout=5):
        """Messages until one satisfies @pred; returns it (None at the deadline or close)."""
        end = time.time() + timeout
        while time.time() < end:
            m = self.recv(timeout=max(0.05, end - time.time()))
            if m is None:
                return None
            if pred(m):
                return m
        return None

    def drop(self):
        """Gone without a close frame (a laptop lid, a pulled cable, a killed browser)."""
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        self.sock.close()

    def close(self):
        try:
            self.sock.sendall(bytes([0x88, 0x80]) + os.urandom(4))
        except OSError:
            pass
        self.sock.close()
