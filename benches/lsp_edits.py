#!/usr/bin/env python3
"""Diagnostics after an edit, through `rcsc lsp` (BENCHMARKS.md, "rcsc lsp").

Starts the server as an editor does (JSON-RPC over stdio), opens FILE, then
makes EDITS edits, each a full-text didChange that alternates between
breaking the first entry row (an unknown name: an error) and fixing it again, and times
each from the didChange sent to the publishDiagnostics received for FILE.
Prints p50, p95 and max in milliseconds.

    python3 benches/machines/generate.py /tmp/mach100 100
    cargo build --release --bin rcsc
    python3 benches/lsp_edits.py target/release/rcsc /tmp/mach100/rcsc/plans/machines/machines.rcs 100
"""
import json
import os
import subprocess
import sys
import time


def send(proc, message):
    body = json.dumps(message).encode()
    proc.stdin.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)
    proc.stdin.flush()


def receive(proc):
    length = None
    while True:
        line = proc.stdout.readline()
        if not line:
            raise SystemExit("rcsc lsp closed its output")
        line = line.strip()
        if not line:
            break
        if line.lower().startswith(b"content-length:"):
            length = int(line.split(b":")[1])
    return json.loads(proc.stdout.read(length))


def until(proc, wanted):
    while True:
        m = receive(proc)
        if wanted(m):
            return m


def main():
    rcsc, path = sys.argv[1], os.path.abspath(sys.argv[2])
    edits = int(sys.argv[3]) if len(sys.argv) > 3 else 100
    uri = "file://" + path
    text = open(path).read()
    # The first entry row, broken by an unknown name in its condition.
    if "when new_command" not in text:
        raise SystemExit("FILE needs an entry row (`when new_command`)")
    broken = text.replace("when new_command", "when nope && new_command", 1)
    proc = subprocess.Popen([rcsc, "lsp"], stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    send(proc, {"jsonrpc": "2.0", "id": 1, "method": "initialize",
                "params": {"processId": None, "rootUri": None, "capabilities": {}}})
    until(proc, lambda m: m.get("id") == 1)
    send(proc, {"jsonrpc": "2.0", "method": "initialized", "params": {}})
    send(proc, {"jsonrpc": "2.0", "method": "textDocument/didOpen",
                "params": {"textDocument": {"uri": uri, "languageId": "rcs", "version": 1, "text": text}}})
    is_ours = lambda m: m.get("method") == "textDocument/publishDiagnostics" and m["params"]["uri"] == uri
    until(proc, is_ours)
    times = []
    errors_seen = 0
    for k in range(edits):
        body = broken if k % 2 == 0 else text
        t0 = time.perf_counter()
        send(proc, {"jsonrpc": "2.0", "method": "textDocument/didChange",
                    "params": {"textDocument": {"uri": uri, "version": k + 2},
                               "contentChanges": [{"text": body}]}})
        m = until(proc, is_ours)
        times.append((time.perf_counter() - t0) * 1000.0)
        errors = [d for d in m["params"]["diagnostics"] if d.get("severity") == 1]
        if k % 2 == 0:
            assert errors, "the broken text has an error"
            errors_seen += 1
        else:
            assert not errors, "the fixed text has none"
    send(proc, {"jsonrpc": "2.0", "id": 2, "method": "shutdown", "params": None})
    until(proc, lambda m: m.get("id") == 2)
    send(proc, {"jsonrpc": "2.0", "method": "exit", "params": None})
    proc.wait(timeout=60)
    times.sort()
    pick = lambda p: times[min(len(times) - 1, round((len(times) - 1) * p))]
    print("%d edits of %s (%d with an error): p50 %.1f ms, p95 %.1f ms, max %.1f ms"
          % (edits, os.path.basename(path), errors_seen, pick(0.5), pick(0.95), times[-1]))


if __name__ == "__main__":
    main()
