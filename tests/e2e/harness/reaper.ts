// Cleanup that survives this process being SIGKILLed: a small detached python3 watchdog whose
// stdin pipe only we hold; when this process dies it reads EOF and removes what we left: our entries in the policy registry (rewriting or deleting the
// managed policy file) and lock directories we own. Normal exits clean up in-process first.
import { spawn } from 'node:child_process';
import type { Socket } from 'node:net';

const REAPER = `
import json, os, sys, time
pid, lock_dir, registry, policy_file, policy_dir = sys.argv[1:6]
sys.stdin.buffer.read()  # returns at EOF: our parent is gone
def alive(p):
    try:
        os.kill(p, 0); return True
    except ProcessLookupError: return False
    except PermissionError: return True
def take_lock(name):
    d = os.path.join(lock_dir, name)
    for _ in range(200):
        try:
            os.makedirs(lock_dir, exist_ok=True); os.mkdir(d)
            with open(os.path.join(d, 'pid'), 'w') as f: f.write(str(os.getpid()))
            return d
        except FileExistsError:
            try: owner = int(open(os.path.join(d, 'pid')).read())
            except Exception: owner = -1
            if owner > 0 and not alive(owner):
                import shutil; shutil.rmtree(d, ignore_errors=True); continue
            time.sleep(0.05)
    return None
def drop(d):
    import shutil; shutil.rmtree(d, ignore_errors=True)
# our locks
if os.path.isdir(lock_dir):
    for name in os.listdir(lock_dir):
        try:
            if open(os.path.join(lock_dir, name, 'pid')).read().strip() == pid: drop(os.path.join(lock_dir, name))
        except Exception: pass
# our policy entries
if os.path.isdir(registry):
    lk = take_lock('chromium-policy')
    try:
        origins = set()
        for name in os.listdir(registry):
            p = os.path.join(registry, name)
            owner = int(name.split('-')[0]) if name.split('-')[0].isdigit() else -1
            if str(owner) == pid or not alive(owner):
                try: os.unlink(p)
                except FileNotFoundError: pass
                continue
            try: origins.add(open(p).read().strip())
            except Exception: pass
        if origins:
            tmp = os.path.join(policy_dir, '.satscope-e2e-serial.reaper.tmp')
            with open(tmp, 'w') as f: json.dump({'SerialAllowAllPortsForUrls': sorted(origins)}, f, indent=2)
            os.rename(tmp, policy_file)
        else:
            try: os.unlink(policy_file)
            except FileNotFoundError: pass
    finally:
        if lk: drop(lk)
`;

let started = false;

/** Start (once per process) the watchdog that cleans up after us if we die without cleanup. */
export function ensureReaper(paths: { lockDir: string; registry: string; policyFile: string; policyDir: string }): void {
  if (started) return;
  started = true;
  const child = spawn('python3', ['-c', REAPER, String(process.pid), paths.lockDir, paths.registry, paths.policyFile, paths.policyDir], {
    stdio: ['pipe', 'ignore', 'ignore'],
    detached: true,
  });
  child.on('error', () => {
    /* no python3: in-process cleanup only */
  });
  (child.stdin as unknown as Socket).unref();
  child.stdin!.on('error', () => undefined);
  child.unref();
}
