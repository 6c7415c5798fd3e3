#!/usr/bin/env python3
"""SatScope e2e harness: a pseudo-terminal standing in for a serial tty (e.g. /dev/ttyS0).

Started by pty-serial.ts; talks over stdio with length-prefixed frames:
  in  (stdin):  <type:1 byte><len:u32 LE><payload>
    W  write payload to the pty master now (after earlier queued writes)
    P  paced write: u32 id, u32 n, n x f64 times (us, relative to job start), n bytes
    H  hang up: close the pty (the page's reader sees the device go away)
    N  new pty in place of the device path (reconnect)
    S  input modem signals for the LD_PRELOAD shim: u32 TIOCM_* bits (CTS, DSR, CD, RI)
    Q  restore the device path and exit
  out (stdout): <type:1 byte><len:u32 LE><payload>
    D  bytes the page wrote: f64 CLOCK_MONOTONIC us, then the bytes
    E  event, UTF-8 JSON
The device path is restored on Q, on stdin EOF (parent died), on SIGTERM/SIGINT/SIGHUP and
on any error: the parent crashing never leaves the pty in place of the real device.

A device sysfs does not list (e.g. /dev/ttyS1 on a machine with one UART) is listed for the
time the pump runs: Chromium enumerates serial ports from sysfs (a tty whose MAJOR/MINOR
/proc/tty/drivers calls "serial") and opens the DEVNAME its uevent names, so an unused virtual
console's uevent is covered (a bind mount) with ttyS0's numbers and this device's name. The mount
is undone by the same restore; a stale one from a killed pump is undone at the next start.
"""
import errno
import json
import os
import select
import signal
import socket
import stat
import struct
import subprocess
import sys
import time
import tty

DEV = sys.argv[1] if len(sys.argv) > 1 else '/dev/ttyS0'
BACKUP = DEV + '.satscope-orig'
COALESCE_S = float(sys.argv[2]) / 1e6 if len(sys.argv) > 2 else 0.0005
SIGNAL_SOCKET = b'\0satscope-pty-signals'
SIGNAL_IN_FILE = '/dev/shm/satscope-pty-signals-in'
NAME = os.path.basename(DEV)
LISTED_IN_SYSFS = os.path.exists(f'/sys/class/tty/{NAME}')
# The virtual consoles lent to unlisted devices, the last ones first (nothing uses them here).
DONORS = [f'/sys/devices/virtual/tty/tty{n}/uevent' for n in range(63, 47, -1)]
UEVENT_FILE = f'/dev/shm/satscope-uevent-{NAME}'

out = sys.stdout.buffer


def now_us():
    return time.monotonic_ns() / 1000.0


def send(kind, payload):
    out.write(kind + struct.pack('<I', len(payload)) + payload)
    out.flush()


def event(**obj):
    obj.setdefault('t', now_us())
    send(b'E', json.dumps(obj).encode())


def is_our_link(path):
    try:
        return stat.S_ISLNK(os.lstat(path).st_mode) and os.readlink(path).startswith('/dev/pts/')
    except FileNotFoundError:
        return False


def mounted_over(path):
    with open('/proc/self/mountinfo') as f:
        return any(line.split()[4] == path for line in f)


def donor_of_ours():
    """The virtual console's uevent this device is listed under (a mount of ours), or None."""
    for donor in DONORS:
        if mounted_over(donor):
            with open(donor) as f:
                if f'DEVNAME={NAME}\n' in f.read():
                    return donor
    return None


def list_device():
    """Make sysfs list DEV (see the module's note), unless it does already."""
    if LISTED_IN_SYSFS or donor_of_ours():
        return
    with open('/sys/class/tty/ttyS0/uevent') as f:
        numbers = [line for line in f.read().splitlines() if line.startswith(('MAJOR=', 'MINOR='))]
    with open(UEVENT_FILE, 'w') as f:
        f.write('\n'.join(numbers + [f'DEVNAME={NAME}']) + '\n')
    donor = next(d for d in DONORS if os.path.exists(d) and not mounted_over(d))
    subprocess.run(['mount', '--bind', UEVENT_FILE, donor], check=True)


def unlist_device():
    donor = donor_of_ours()
    if donor:
        subprocess.run(['umount', donor], check=False)
    try:
        os.unlink(UEVENT_FILE)
    except FileNotFoundError:
        pass


def restore():
    """Idempotent: remove our symlink, move the original device back, unlist a listed one."""
    unlist_device()
    if is_our_link(DEV):
        os.unlink(DEV)
    if is_our_link(DEV + '.satscope-new'):
        os.unlink(DEV + '.satscope-new')
    if os.path.lexists(BACKUP) and not os.path.lexists(DEV):
        try:
            os.rename(BACKUP, DEV)
        except FileNotFoundError:
            pass  # restored concurrently by pty-serial.ts
    try:
        os.unlink(SIGNAL_IN_FILE)
    except FileNotFoundError:
        pass


def install(slave_path):
    """Put a symlink to the pty slave at DEV, atomically, keeping the original as BACKUP."""
    if not os.path.lexists(BACKUP):
        if os.path.lexists(DEV):
            os.rename(DEV, BACKUP)
    elif os.path.lexists(DEV) and not is_our_link(DEV):
        raise RuntimeError(f'{DEV} and {BACKUP} both exist and {DEV} is not a harness symlink')
    tmp = DEV + '.satscope-new'
    if os.path.lexists(tmp):
        os.unlink(tmp)
    os.symlink(slave_path, tmp)
    os.rename(tmp, DEV)


class Pty:
    def __init__(self):
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)  # no echo / line editing before the browser configures it
        os.set_blocking(self.master, False)
        self.path = os.ttyname(self.slave)

    def close(self):
        for fd in (self.master, self.slave):
            try:
                os.close(fd)
            except OSError:
                pass


pty = None
queue = []  # segments: [due_s or None (start of job), bytearray, job]
jobs = {}
inbuf = bytearray()
signals_in = 0


def new_pty():
    global pty
    if pty:
        pty.close()
    pty = Pty()
    install(pty.path)
    event(type='ready', path=DEV, pts=pty.path)


def hangup():
    global pty
    for seg in queue:
        job = seg[2]
        if job and not job.get('reported'):
            job['reported'] = True
            event(type='paced', id=job['id'], ok=False, reason='hangup')
    queue.clear()
    if pty:
        pty.close()
        pty = None
    event(type='hungup')


def add_paced(job_id, times, data):
    job = {'id': job_id, 'start': None, 'late_max': 0.0, 'n': len(data), 'times': times}
    # coalesce bytes due within COALESCE_S of a segment's first byte into one write
    segs = []
    i = 0
    n = len(data)
    while i < n:
        t0 = times[i]
        j = i + 1
        while j < n and times[j] - t0 <= COALESCE_S * 1e6:
            j += 1
        segs.append([t0 / 1e6, bytearray(data[i:j]), job])
        i = j
    if not segs:
        event(type='paced', id=job_id, ok=True, lateMaxUs=0, bytes=0)
        return
    segs[-1].append('last')
    queue.extend(segs)


def handle(kind, payload):
    global signals_in
    if kind == b'W':
        queue.append([None, bytearray(payload), None])
    elif kind == b'P':
        job_id, n = struct.unpack_from('<II', payload, 0)
        times = struct.unpack_from(f'<{n}d', payload, 8)
        data = payload[8 + 8 * n: 8 + 9 * n]
        add_paced(job_id, times, data)
    elif kind == b'H':
        hangup()
    elif kind == b'N':
        if pty is not None:
            hangup()
        new_pty()
    elif kind == b'S':
        (signals_in,) = struct.unpack_from('<I', payload, 0)
        tmp = SIGNAL_IN_FILE + '.tmp'
        with open(tmp, 'w') as f:
            f.write(str(signals_in))
        os.rename(tmp, SIGNAL_IN_FILE)
        event(type='signals-in', bits=signals_in)
    elif kind == b'Q':
        raise SystemExit(0)


def pump_out():
    """Write due segments. Returns seconds until the next due segment, or None."""
    while queue and pty:
        seg = queue[0]
        due, data, job = seg[0], seg[1], seg[2]
        t = time.monotonic()
        if job is not None:
            if job['start'] is None:
                job['start'] = t
            at = job['start'] + due
            if at > t:
                return at - t
            late = (t - at) * 1e6
            if late > job['late_max']:
                job['late_max'] = late
        try:
            written = os.write(pty.master, data)
        except BlockingIOError:
            return 0.002  # pty buffer full: the page is not reading; retry soon
        del data[:written]
        if data:
            return 0.002
        queue.pop(0)
        if job is not None and len(seg) > 3:
            job['reported'] = True
            event(type='paced', id=job['id'], ok=True, lateMaxUs=round(job['late_max']), bytes=job['n'])
    return None


def main():
    def stop(*_):
        raise SystemExit(0)

    for s in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        signal.signal(s, stop)
    sig = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    try:
        sig.bind(SIGNAL_SOCKET)
    except OSError:
        sig.close()
        sig = None
    restore()  # a stale swap from a crashed run
    list_device()
    new_pty()
    os.set_blocking(0, False)
    while True:
        timeout = pump_out()
        rl = [0]
        if pty:
            rl.append(pty.master)
        if sig:
            rl.append(sig)
        wl = [pty.master] if (pty and queue and timeout == 0.002) else []
        r, w, _ = select.select(rl, wl, [], timeout)
        if pty and pty.master in r:
            try:
                data = os.read(pty.master, 65536)
                if data:
                    send(b'D', struct.pack('<d', now_us()) + data)
            except BlockingIOError:
                pass
            except OSError as e:
                if e.errno != errno.EIO:
                    raise
        if sig and sig in r:
            msg = sig.recv(256)
            # from the shim: "<op> <bits> <t_us>"
            op, bits, t = msg.decode().split()
            event(type='signals', op=op, bits=int(bits), t=float(t))
        if 0 in r:
            try:
                chunk = os.read(0, 1 << 20)
            except BlockingIOError:
                continue
            if not chunk:
                raise SystemExit(0)  # parent gone
            inbuf.extend(chunk)
            while len(inbuf) >= 5:
                (length,) = struct.unpack_from('<I', inbuf, 1)
                if len(inbuf) < 5 + length:
                    break
                kind = bytes(inbuf[0:1])
                payload = bytes(inbuf[5:5 + length])
                del inbuf[:5 + length]
                handle(kind, payload)


if __name__ == '__main__':
    code = 0
    try:
        main()
    except SystemExit as e:
        code = e.code or 0
    except BaseException as e:  # noqa: BLE001 - report anything, then restore
        code = 1
        try:
            event(type='error', message=f'{type(e).__name__}: {e}')
        except Exception:
            pass
    finally:
        if pty:
            pty.close()
        try:
            restore()
        except Exception as e:  # noqa: BLE001
            sys.stderr.write(f'pty-pump: restore failed: {e}\n')
            code = code or 2
    sys.exit(code)
