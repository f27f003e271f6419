#!/usr/bin/env python3
"""A stand-in tev viewer that reads and discards (docs/benchmarks.md, "Streaming to a viewer"):
listens on 127.0.0.1:PORT and swallows every connection's bytes, so that
`nimbus render --display-server 127.0.0.1:PORT` can be timed without a viewer's own cost.

Usage: tools/tev_sink.py PORT     (runs until killed)
"""
import socket
import sys
import threading


def swallow(conn):
    with conn:
        while conn.recv(1 << 16):
            pass


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    server = socket.socket()
    server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    server.bind(("127.0.0.1", int(sys.argv[1])))
    server.listen(8)
    while True:
        conn, _ = server.accept()
        threading.Thread(target=swallow, args=(conn,), daemon=True).start()


if __name__ == "__main__":
    main()
