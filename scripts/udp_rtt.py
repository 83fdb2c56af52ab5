#!/usr/bin/env python3
"""UDP echo round trip on 127.0.0.1 (a ping for scripts/netem.sh, run inside its namespace):
sends N probes, one every INTERVAL ms, to an echo thread in this process and prints the
round trip's p50/p99/max and the probes lost (a lost probe waits TIMEOUT ms).
  scripts/udp_rtt.py [N=300] [INTERVAL_MS=2] [TIMEOUT_MS=200]"""
import socket
import sys
import threading
import time

n = int(sys.argv[1]) if len(sys.argv) > 1 else 300
interval = (float(sys.argv[2]) if len(sys.argv) > 2 else 2.0) / 1000.0
timeout = (float(sys.argv[3]) if len(sys.argv) > 3 else 200.0) / 1000.0

server = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
server.bind(("127.0.0.1", 0))


def echo():
    while True:
        data, peer = server.recvfrom(64)
        server.sendto(data, peer)


threading.Thread(target=echo, daemon=True).start()
client = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
client.settimeout(timeout)
rtts, lost = [], 0
for i in range(n):
    start = time.perf_counter()
    client.sendto(i.to_bytes(4, "little"), server.getsockname())
    try:
        while True:  # skip late echoes of earlier probes
            data = client.recv(64)
            if int.from_bytes(data, "little") == i:
                rtts.append((time.perf_counter() - start) * 1000.0)
                break
    except socket.timeout:
        lost += 1
    time.sleep(interval)
rtts.sort()
if rtts:
    def q(p):
        return rtts[min(len(rtts) - 1, int(p * len(rtts)))]
    print(f"udp echo round trip: p50 {q(0.5):.2f} ms, p99 {q(0.99):.2f} ms, max {rtts[-1]:.2f} ms, "
          f"{lost} of {n} probes lost")
else:
    print(f"udp echo round trip: all {n} probes lost")
