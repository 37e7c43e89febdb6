"""A slowloris attack on loopback, for the preview's test (test_preview.py) and its benchmark
(bench/preview_overhead.py): connections that each send a request line and a header byte a second and
never end their request, reopened as the server closes them."""
import socket
import time


class SlowClients:
    def __init__(self, port, count):
        self.port, self.count = port, count
        self.clients, self.next_byte = [], time.time()

    def refill(self):
        """Opens connections up to `count`, each with an unfinished request (a loopback port that
        refuses is left until the next call)."""
        while len(self.clients) < self.count:
            try:
                c = socket.create_connection(("127.0.0.1", self.port), timeout=1)
            except OSError:
                return
            c.setblocking(False)
            c.send(f"GET /status HTTP/1.1\r\nHost: 127.0.0.1:{self.port}\r\n".encode())
            self.clients.append(c)

    def drip(self):
        """Once a second: one more header byte on each connection; those the server closed are dropped.
        True when it was time to send."""
        if time.time() < self.next_byte:
            return False
        self.next_byte = time.time() + 1
        alive = []
        for c in self.clients:
            try:
                c.send(b"X")
                if c.recv(4096) == b"":
                    raise OSError("closed")
            except BlockingIOError:
                pass
            except OSError:
                c.close()
                continue
            alive.append(c)
        self.clients = alive
        return True

    def close(self):
        for c in self.clients:
            c.close()
        self.clients = []
