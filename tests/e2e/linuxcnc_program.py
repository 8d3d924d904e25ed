#!/usr/bin/env python3
"""Runs a G-code program on a running LinuxCNC through linuxcncrsh (the e2e's own client: the
product's link sends one MDI line per update and never runs programs). Out of e-stop, machine on,
LinuxCNC's homing, then AUTO mode, open, run, and wait until the program has ended; its errors
printed. Exit 0 when the program ran to its end with no error, 1 otherwise.

usage: linuxcnc_program.py PROGRAM [--port 5007] [--connectpw PW] [--enablepw PW] [--timeout S]
       [--feed-override PERCENT]
"""
import argparse
import socket
import sys
import time


class Rsh:
    def __init__(self, port, timeout):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=timeout)
        self.buffer = b""

    def line(self, deadline):
        while b"\n" not in self.buffer:
            self.sock.settimeout(max(0.1, deadline - time.monotonic()))
            chunk = self.sock.recv(4096)
            if not chunk:
                raise RuntimeError("linuxcncrsh closed the connection")
            self.buffer += chunk
        text, self.buffer = self.buffer.split(b"\n", 1)
        return text.decode(errors="replace").strip("\r\n ")

    def ask(self, command, want, timeout=10.0):
        """Sends `command` and returns the first reply line starting with `want` (set: the ACK/NAK)."""
        self.sock.sendall((command + "\r\n").encode())
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            reply = self.line(deadline)
            if reply.upper().startswith(want.upper()):
                return reply
        raise RuntimeError(f"no answer to {command.split()[0]} {command.split()[1] if len(command.split()) > 1 else ''}")

    def set(self, command, word):
        reply = self.ask("set " + command, "SET " + word)
        if not reply.upper().endswith("ACK"):
            raise RuntimeError(f"LinuxCNC refused 'set {command.split()[0]}': {reply}")

    def value(self, what):
        reply = self.ask("get " + what, what.upper())
        parts = reply.split(None, 1)
        return parts[1] if len(parts) > 1 else ""

    def errors(self):
        found = []
        for _ in range(20):
            text = self.value("error")
            if text.upper() == "OK":
                break
            found.append(text)
        return found


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("program")
    parser.add_argument("--port", type=int, default=5007)
    parser.add_argument("--connectpw", default="SimMillHello")
    parser.add_argument("--enablepw", default="SimMillEnable")
    parser.add_argument("--timeout", type=float, default=600.0, help="seconds the program may run")
    parser.add_argument("--feed-override", type=int, default=100,
                        help="percent (a measurement's shortcut: within the INI's MAX_FEED_OVERRIDE)")
    args = parser.parse_args()
    rsh = Rsh(args.port, 10.0)
    rsh.ask(f"hello {args.connectpw} stencil-e2e 1.1", "HELLO ACK")
    rsh.sock.sendall(b"set echo off\r\n")
    time.sleep(0.3)
    rsh.buffer = b""
    rsh.set("verbose on", "VERBOSE")
    rsh.set(f"enable {args.enablepw}", "ENABLE")
    old = rsh.errors()
    if old:
        print("dropped LinuxCNC's old errors: " + "; ".join(old))
    rsh.set("estop off", "ESTOP")
    rsh.set("machine on", "MACHINE")
    rsh.set("mode manual", "MODE")
    rsh.set("teleop_enable off", "TELEOP_ENABLE")
    rsh.set("home -1", "HOME")
    deadline = time.monotonic() + 30.0
    while "NO" in rsh.value("joint_homed").upper().split()[:3]:  # it lists every joint LinuxCNC could have
        if time.monotonic() > deadline:
            raise RuntimeError("LinuxCNC did not home in 30 s")
        time.sleep(0.2)
    rsh.set("mode auto", "MODE")
    rsh.set(f"open {args.program}", "OPEN")
    if args.feed_override != 100:
        rsh.set(f"feed_override {args.feed_override}", "FEED_OVERRIDE")
    started = time.monotonic()
    rsh.set("run", "RUN")
    status = ""
    time.sleep(0.5)
    while time.monotonic() - started < args.timeout:
        status = rsh.value("program_status").upper()
        if status == "IDLE":
            break
        errors = rsh.errors()
        if errors:
            print("LinuxCNC: " + "; ".join(errors), file=sys.stderr)
            return 1
        time.sleep(0.5)
    elapsed = time.monotonic() - started
    errors = rsh.errors()
    if status != "IDLE":
        print(f"the program still ran after {args.timeout:.0f} s", file=sys.stderr)
        return 1
    if errors:
        print("LinuxCNC: " + "; ".join(errors), file=sys.stderr)
        return 1
    print(f"program ran to its end in {elapsed:.1f} s")
    rsh.set("machine off", "MACHINE")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except (OSError, RuntimeError) as error:
        print(f"linuxcnc_program: {error}", file=sys.stderr)
        sys.exit(1)
