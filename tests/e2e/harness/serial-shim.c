/*
 * SatScope e2e harness: LD_PRELOAD shim giving pseudo-terminals modem control lines.
 *
 * Linux ptys implement no TIOCMGET/TIOCMSET, so Chromium's SerialPort.setSignals() and
 * getSignals() fail with NetworkError on a pty. Preloaded into Chromium, this shim answers
 * those ioctls for pty slaves (char major 136-143) only: it keeps DTR/RTS (and BREAK) in
 * memory, reports every change as a datagram "<op> <TIOCM bits> <CLOCK_MONOTONIC us>" to
 * the abstract unix socket "@satscope-pty-signals" (pty-pump.py), and reads the input lines
 * (CTS/DSR/CD/RI) from /dev/shm/satscope-pty-signals-in. Every other ioctl passes through.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

static int (*real_ioctl)(int, unsigned long, ...);
static int out_bits = 0;

static int is_pty_slave(int fd) {
  struct stat st;
  if (fstat(fd, &st) != 0 || !S_ISCHR(st.st_mode)) return 0;
  unsigned int maj = major(st.st_rdev);
  return maj >= 136 && maj <= 143;
}

static int input_bits(void) {
  int bits = TIOCM_CTS | TIOCM_DSR | TIOCM_CD;
  int fd = open("/dev/shm/satscope-pty-signals-in", O_RDONLY | O_CLOEXEC);
  if (fd >= 0) {
    char buf[32];
    ssize_t n = read(fd, buf, sizeof buf - 1);
    if (n > 0) { buf[n] = 0; bits = atoi(buf); }
    close(fd);
  }
  return bits & (TIOCM_CTS | TIOCM_DSR | TIOCM_CD | TIOCM_RI);
}

static void report(const char *op, int bits) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  char msg[96];
  int n = snprintf(msg, sizeof msg, "%s %d %.3f", op, bits,
                   ts.tv_sec * 1e6 + ts.tv_nsec / 1e3);
  int s = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (s < 0) return;
  struct sockaddr_un addr;
  memset(&addr, 0, sizeof addr);
  addr.sun_family = AF_UNIX;
  static const char name[] = "\0satscope-pty-signals";
  memcpy(addr.sun_path, name, sizeof name - 1);
  sendto(s, msg, n, MSG_DONTWAIT, (struct sockaddr *)&addr,
         offsetof(struct sockaddr_un, sun_path) + sizeof name - 1);
  close(s);
}

int ioctl(int fd, unsigned long request, ...) {
  va_list ap;
  va_start(ap, request);
  void *arg = va_arg(ap, void *);
  va_end(ap);
  if (!real_ioctl) real_ioctl = dlsym(RTLD_NEXT, "ioctl");
  switch (request) {
    case TIOCMGET:
    case TIOCMSET:
    case TIOCMBIS:
    case TIOCMBIC:
    case TIOCSBRK:
    case TIOCCBRK:
      if (is_pty_slave(fd)) {
        int mask = TIOCM_DTR | TIOCM_RTS;
        int cur = __atomic_load_n(&out_bits, __ATOMIC_SEQ_CST);
        if (request == TIOCMGET) {
          *(int *)arg = cur | input_bits();
          return 0;
        }
        if (request == TIOCSBRK || request == TIOCCBRK) {
          report(request == TIOCSBRK ? "break-on" : "break-off", cur);
          return 0;
        }
        int v = *(int *)arg & mask;
        int next = request == TIOCMSET ? v : request == TIOCMBIS ? (cur | v) : (cur & ~v);
        __atomic_store_n(&out_bits, next, __ATOMIC_SEQ_CST);
        report("set", next);
        return 0;
      }
      break;
  }
  return real_ioctl(fd, request, arg);
}
