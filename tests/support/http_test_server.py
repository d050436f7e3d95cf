#!/usr/bin/python3
"""Loopback HTTP/1.1 file server for resoct's HTTP tests and benchmarks.

Usage: http_test_server.py ROOT
Serves the files below ROOT on 127.0.0.1 at a free port (bound as port 0) and prints
"PORT <n>" as its first line. Exits when its standard input reaches EOF, so it cannot outlive
the test process that started it.

The first path component selects a behaviour, the rest names the file below ROOT:
  /ok/F        GET and HEAD with Range support (206 + Content-Range, 416 past the end),
               suffix ranges "bytes=-N" included
  /nosuffix/F  like /ok, but answers a suffix range "bytes=-N" with 200 and the whole file (as
               servers that implement only first-last ranges do)
  /norange/F   ignores Range headers (always 200 with the whole file)
  /missing/F   404
  /flaky/F     500 for the first two requests of each path, then like /ok
  /fail/F      always 500
  /truncate/F  announces the full Content-Length, sends half the body, closes the connection
  /stall/F     accepts the request and sends nothing for 60 s
  /redirect-ok/F    302 to /ok/F on this server (a relative Location)
  /redirect-loop/F  302 to itself
  /redirect-host/F  302 to http://localhost:<this port>/ok/F (same server, another host name)
  /redirect-port/F  302 to http://127.0.0.1:<another port>/ok/F
  /redirect-https/F 302 to https://127.0.0.1:<this port>/ok/F (another scheme)
  /redirect-file/F  302 to file:///etc/passwd
  /redirect-ftp/F   302 to ftp://127.0.0.1/F
  /busy/F      503 with "Retry-After: 1" for the first request of each path, then like /ok
  /chaos/F     like /ok, except that each request draws, with the probability set by /_chaos, one
               fault at random: 404, 500, 503 with Retry-After, a truncated body, a wrong
               Content-Range, a stall past the client's timeout, or a connection reset
  /_chaos/P/S  sets the /chaos fault probability to P per mille (0: healed) and reseeds its
               random generator with S, so a run's faults repeat for the same request order
  /_stats      JSON {"connections": n, "requests": n, "faults": {kind: n}} since start or the
               last /_reset
  /_reset      zeroes the counters and the /flaky and /busy attempt counts
"""
import http.server
import json
import os
import re
import random
import socket
import struct
import sys
import threading
import time

ROOT = os.path.realpath(sys.argv[1])
LOCK = threading.Lock()
STATS = {"connections": 0, "requests": 0, "faults": {}}
FLAKY = {}
CHAOS = {"permille": 0, "rng": random.Random(0)}
FAULTS = ("404", "500", "503", "truncate", "bad_range", "stall", "reset")
# A stall outlasts any client timeout the tests set (fault-injection options: 1.5 s at most).
STALL_S = 3.0


class Handler(http.server.BaseHTTPRequestHandler):
    protocol_version = "HTTP/1.1"

    def setup(self):
        super().setup()
        # Headers and body go out in separate writes; without this, Nagle's algorithm and the
        # client's delayed ACK add 40 ms to every response.
        self.connection.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        with LOCK:
            STATS["connections"] += 1

    def log_message(self, *args):
        pass

    def send_bytes(self, code, body, extra=(), send_body=True):
        self.send_response(code)
        self.send_header("Content-Length", str(len(body)))
        for k, v in extra:
            self.send_header(k, v)
        self.end_headers()
        if send_body:
            self.wfile.write(body)

    def do_HEAD(self):
        self.handle_request(send_body=False)

    def do_GET(self):
        self.handle_request(send_body=True)

    def handle_request(self, send_body):
        with LOCK:
            STATS["requests"] += 1
        parts = self.path.split("?")[0].lstrip("/").split("/", 1)
        mode = parts[0]
        if mode == "_stats":
            with LOCK:
                body = json.dumps(STATS).encode()
            return self.send_bytes(200, body, send_body=send_body)
        if mode == "_reset":
            with LOCK:
                STATS["connections"] = 0
                STATS["requests"] = 0
                STATS["faults"] = {}
                FLAKY.clear()
            return self.send_bytes(200, b"{}", send_body=send_body)
        if mode == "_chaos":
            args = (parts[1] if len(parts) > 1 else "").split("/")
            try:
                permille, seed = int(args[0]), int(args[1])
            except (IndexError, ValueError):
                return self.send_bytes(400, b"usage: /_chaos/PERMILLE/SEED", send_body=send_body)
            with LOCK:
                CHAOS["permille"] = max(0, min(1000, permille))
                CHAOS["rng"] = random.Random(seed)
            return self.send_bytes(200, b"{}", send_body=send_body)
        rel = parts[1] if len(parts) > 1 else ""
        if mode.startswith("redirect-"):
            port = self.server.server_address[1]
            target = {
                "redirect-ok": "/ok/" + rel,
                "redirect-loop": "/redirect-loop/" + rel,
                "redirect-host": "http://localhost:%d/ok/%s" % (port, rel),
                "redirect-port": "http://127.0.0.1:%d/ok/%s" % (port + 1 if port < 65535 else 1, rel),
                "redirect-https": "https://127.0.0.1:%d/ok/%s" % (port, rel),
                "redirect-file": "file:///etc/passwd",
                "redirect-ftp": "ftp://127.0.0.1/" + rel,
            }.get(mode)
            if target is None:
                return self.send_bytes(400, b"unknown mode", send_body=send_body)
            return self.send_bytes(302, b"moved", [("Location", target)], send_body)
        path = os.path.realpath(os.path.join(ROOT, rel))
        if mode == "missing" or not path.startswith(ROOT + os.sep) or not os.path.isfile(path):
            return self.send_bytes(404, b"not found", send_body=send_body)
        if mode == "fail":
            return self.send_bytes(500, b"server error", send_body=send_body)
        if mode == "flaky":
            with LOCK:
                FLAKY[rel] = FLAKY.get(rel, 0) + 1
                n = FLAKY[rel]
            if n <= 2:
                return self.send_bytes(500, b"try again", send_body=send_body)
        if mode == "busy":
            with LOCK:
                FLAKY["busy/" + rel] = FLAKY.get("busy/" + rel, 0) + 1
                n = FLAKY["busy/" + rel]
            if n <= 1:
                return self.send_bytes(503, b"busy", [("Retry-After", "1")], send_body)
        if mode == "stall":
            time.sleep(60)
            return
        size = os.path.getsize(path)
        fault = None
        if mode == "chaos":
            with LOCK:
                rng = CHAOS["rng"]
                if rng.randrange(1000) < CHAOS["permille"]:
                    fault = rng.choice(FAULTS)
                    STATS["faults"][fault] = STATS["faults"].get(fault, 0) + 1
            if fault == "404":
                return self.send_bytes(404, b"not found", send_body=send_body)
            if fault == "500":
                return self.send_bytes(500, b"server error", send_body=send_body)
            if fault == "503":
                return self.send_bytes(503, b"busy", [("Retry-After", "1")], send_body)
            if fault == "stall":
                time.sleep(STALL_S)
                self.close_connection = True
                return
            if fault == "reset":
                # SO_LINGER with a zero timeout: close() sends a TCP RST instead of a FIN.
                self.connection.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER,
                                           struct.pack("ii", 1, 0))
                self.connection.close()
                self.close_connection = True
                return
            if fault == "truncate":
                mode = "truncate"

        def read(first, count):
            # Only the bytes sent: whole-file reads would make every range request cost the file.
            with open(path, "rb") as f:
                f.seek(first)
                return f.read(count)

        if mode == "truncate":
            self.send_response(200)
            self.send_header("Content-Length", str(size))
            self.send_header("Connection", "close")
            self.end_headers()
            if send_body:
                self.wfile.write(read(0, size // 2))
                self.wfile.flush()
            self.close_connection = True
            return
        if mode not in ("ok", "flaky", "norange", "nosuffix", "busy", "chaos"):
            return self.send_bytes(400, b"unknown mode", send_body=send_body)
        rng = self.headers.get("Range")
        if mode == "norange" or rng is None:
            if not send_body:  # HEAD: the size without reading the file
                self.send_response(200)
                self.send_header("Content-Length", str(size))
                self.send_header("Accept-Ranges", "bytes")
                self.end_headers()
                return
            return self.send_bytes(200, read(0, size), [("Accept-Ranges", "bytes")])
        suffix = re.fullmatch(r"bytes=-(\d+)", rng.strip())
        if suffix and mode == "nosuffix":
            return self.send_bytes(200, read(0, size), [("Accept-Ranges", "bytes")], send_body)
        if suffix and int(suffix.group(1)) > 0 and size > 0:
            first = max(0, size - int(suffix.group(1)))
            return self.send_bytes(206, read(first, size - first),
                                   [("Content-Range", "bytes %d-%d/%d" % (first, size - 1, size))],
                                   send_body)
        m = re.fullmatch(r"bytes=(\d+)-(\d*)", rng.strip())
        if not m:
            return self.send_bytes(400, b"bad range", send_body=send_body)
        first = int(m.group(1))
        last = int(m.group(2)) if m.group(2) else size - 1
        if first >= size:
            return self.send_bytes(416, b"", [("Content-Range", "bytes */%d" % size)], send_body)
        last = min(last, size - 1)
        if fault == "bad_range":
            # The bytes of another range than the one asked for, labelled as such.
            first = first + 1 if last + 1 < size else max(0, first - 1)
            last = min(size - 1, first + (last - first))
        self.send_bytes(206, read(first, last + 1 - first),
                        [("Content-Range", "bytes %d-%d/%d" % (first, last, size))], send_body)


class Server(http.server.ThreadingHTTPServer):
    daemon_threads = True

    def handle_error(self, request, client_address):
        pass  # clients abort transfers on purpose (size limits, ranges from a 200 answer)


def main():
    server = Server(("127.0.0.1", 0), Handler)
    print("PORT %d" % server.server_address[1], flush=True)

    def watch_parent():
        sys.stdin.read()
        os._exit(0)

    threading.Thread(target=watch_parent, daemon=True).start()
    server.serve_forever()


if __name__ == "__main__":
    main()
