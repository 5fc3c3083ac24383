/* SPDX-License-Identifier: Apache-2.0 */
/*
 * syscount: counts the system calls libccomm's real-time calls make, per call.
 *
 *   syscount SLEEPY_NODE BUSY_NODE [CALLS]
 *
 *   syscount --board-clock SLEEPY_NODE BUSY_NODE [CALLS]   (under LD_PRELOAD=board_clock.so)
 *
 * Forks a child that runs loops of ccomm_read / ccomm_write / ccomm_flush in each
 * doorbell mode (default, CCOMM_OPEN_NO_DOORBELL, CCOMM_OPEN_BATCH) against a ccommd
 * that sleeps between frames (SLEEPY_NODE, spin_us 0) and one that never sleeps
 * (BUSY_NODE, spin_us >= its heartbeat). The parent traces the child with ptrace
 * (PTRACE_O_TRACESYSGOOD syscall stops, PTRACE_GET_SYSCALL_INFO: any architecture) and
 * counts the syscalls made between two markers -- write(-1, "begin PHASE ...") and
 * write(-1, "end") -- which the child makes around each loop ("pause" and "resume"
 * leave out the sleeps of paced loops). Each phase has a bound
 * per call and a least total (a phase that must wake someone has to show it did), and
 * a self-check phase of getppid() calls proves the counter counts. Exit 0 if every
 * phase is within its bounds, 1 otherwise, 2 on a usage or set-up error, 4 when
 * ptrace is not permitted. --board-clock: the loops of board_clock_workload (below), the
 * clock readings of reads, writes and a whole control cycle on a board without a vDSO clock.
 */
#define _GNU_SOURCE
#include <ccomm/ccomm.h>
#include <errno.h>
#include <linux/ptrace.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/syscall.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "ccomm_blk.h" /* the Simulink blocks' C layer (integrations/simulink) */

/* glibc's <sys/ptrace.h> clashes with <linux/ptrace.h> (which has ptrace_syscall_info):
 * the raw system call instead. */
#define ptrace(req, pid, addr, data) syscall(SYS_ptrace, (long)(req), (long)(pid), (long)(addr), (long)(data))

#define MAX_NR 1024
#define MAX_PHASES 16

/* ---- the child: the workload ------------------------------------------------------ */

static void marker(const char* text) {
  /* A write to fd -1 fails (EBADF) without side effects; the tracer reads its text. */
  if (write(-1, text, strlen(text)) != -1) _exit(3);
}

static void begin(const char* phase, long calls, double max_per_call, long min_total) {
  char text[160];
  snprintf(text, sizeof text, "begin %s %ld %g %ld", phase, calls, max_per_call, min_total);
  marker(text);
}

static void end(void) { marker("end"); }

static void sleep_ms(long ms);

/* Sleeps 1 ms without counting the sleep's syscalls. */
static void pause_count(void) {
  marker("pause");
  sleep_ms(1);
  marker("resume");
}

static ccomm_client* open_or_die(const char* node, uint32_t flags) {
  ccomm_client* c = NULL;
  int r = ccomm_open(node, flags, &c);
  if (r != 0) {
    fprintf(stderr, "syscount: ccomm_open(%s): %s\n", node, ccomm_strerror(r));
    _exit(2);
  }
  return c;
}

static ccomm_signal find_or_die(ccomm_client* c, const char* name) {
  ccomm_signal s = ccomm_find(c, name);
  if (s < 0) {
    fprintf(stderr, "syscount: no signal %s on node %s\n", name, ccomm_node_name(c));
    _exit(2);
  }
  return s;
}

static void must(int r, const char* what) {
  if (r < 0) {
    fprintf(stderr, "syscount: %s: %s\n", what, ccomm_strerror(r));
    _exit(2);
  }
}

static void sleep_ms(long ms) {
  struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
  while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
  }
}

/* A separate (untraced) process that keeps a ccomm_wait() pending on `node`. */
static pid_t start_waiter(const char* node) {
  pid_t p = fork();
  if (p == 0) {
    ccomm_client* w = open_or_die(node, 0);
    for (;;) ccomm_wait(w, 1000);
  }
  sleep_ms(300); /* until it waits (ccomm_wait registers before it sleeps) */
  return p;
}

static void workload(const char* sleepy, const char* busy, long n) {
  ccomm_client* plain = open_or_die(sleepy, 0);
  ccomm_client* quiet = open_or_die(sleepy, CCOMM_OPEN_NO_DOORBELL);
  ccomm_client* batch = open_or_die(sleepy, CCOMM_OPEN_BATCH);
  ccomm_client* awake = open_or_die(busy, 0);
  ccomm_signal fwd = find_or_die(plain, "sleepy_state");  /* forwarded, event-driven */
  ccomm_signal local = find_or_die(plain, "sleepy_local"); /* not forwarded */
  ccomm_signal rx = find_or_die(plain, "busy_state");      /* received from the busy node */
  ccomm_signal busy_fwd = find_or_die(awake, "busy_state");
  double v = 0;
  ccomm_info info;
  long i;

  /* The counter itself: one getppid() per call, exactly. */
  begin("self-check:getppid", n, 1, n);
  for (i = 0; i < n; ++i) syscall(SYS_getppid);
  end();

  /* The first write of a process: no lazy set-up (pid cache...) may happen in it. */
  begin("write:first-in-process,NO_DOORBELL", 1, 0, 0);
  must(ccomm_write_double(quiet, fwd, 1.0), "first write");
  end();
  sleep_ms(200); /* let ccommd go back to sleep */
  begin("read:own-state", n, 0, 0);
  for (i = 0; i < n; ++i) must(ccomm_read_double(plain, fwd, &v, &info), "read sleepy_state");
  end();
  begin("read:received-state", n, 0, 0);
  for (i = 0; i < n; ++i) must(ccomm_read_double(plain, rx, &v, &info), "read busy_state");
  end();
  begin("write:NO_DOORBELL", n, 0, 0);
  for (i = 0; i < n; ++i) must(ccomm_write_double(quiet, fwd, (double)i), "write (no doorbell)");
  end();
  begin("write+flush:NO_DOORBELL", n, 0, 0);
  for (i = 0; i < n; ++i) {
    must(ccomm_write_double(quiet, fwd, (double)i), "write (no doorbell)");
    must(ccomm_flush(quiet), "flush (no doorbell)");
  }
  end();
  begin("write:BATCH", n, 0, 0);
  for (i = 0; i < n; ++i) must(ccomm_write_double(batch, fwd, (double)i), "write (batch)");
  end();
  must(ccomm_flush(batch), "flush (batch)");
  sleep_ms(200);
  begin("write+flush:BATCH,ccommd-asleep", n, 1, 1);
  for (i = 0; i < n; ++i) {
    must(ccomm_write_double(batch, fwd, (double)i), "write (batch)");
    must(ccomm_flush(batch), "flush (batch)");
  }
  end();
  sleep_ms(200);
  begin("write:default,ccommd-asleep", n, 1, 1);
  for (i = 0; i < n; ++i) must(ccomm_write_double(plain, fwd, (double)i), "write (default)");
  end();
  /* As a 1 kHz control loop: ccommd is back asleep at every write. The sleeps between
   * the calls are not counted (pause/resume markers). */
  long paced = n / 100 > 50 ? n / 100 : 50;
  begin("write:default,ccommd-asleep,1kHz", paced, 1, 1);
  for (i = 0; i < paced; ++i) {
    must(ccomm_write_double(plain, fwd, (double)i), "write (default)");
    pause_count();
  }
  end();
  begin("write+flush:BATCH,ccommd-asleep,1kHz", paced, 1, 1);
  for (i = 0; i < paced; ++i) {
    must(ccomm_write_double(batch, fwd, (double)i), "write (batch)");
    must(ccomm_flush(batch), "flush (batch)");
    pause_count();
  }
  end();
  begin("write:default,local-signal", n, 0, 0);
  for (i = 0; i < n; ++i) must(ccomm_write_double(plain, local, (double)i), "write local");
  end();
  begin("write:default,ccommd-awake", n, 0, 0);
  for (i = 0; i < n; ++i) must(ccomm_write_double(awake, busy_fwd, (double)i), "write (busy node)");
  end();

  pid_t waiter = start_waiter(sleepy);
  begin("write:default,local-signal,1-waiter", n, 1, 1);
  for (i = 0; i < n; ++i) must(ccomm_write_double(plain, local, (double)i), "write local");
  end();
  begin("write:NO_DOORBELL,local-signal,1-waiter", n, 0, 0);
  for (i = 0; i < n; ++i) must(ccomm_write_double(quiet, local, (double)i), "write local (no doorbell)");
  end();
  kill(waiter, SIGKILL);
  waitpid(waiter, NULL, 0);

  ccomm_close(awake);
  ccomm_close(batch);
  ccomm_close(quiet);
  ccomm_close(plain);
}

/* The loops of a control cycle on a board whose clock reading is a system call (run
 * under board_clock.so, see there): each call that reads the clock shows as one
 * clock_gettime. A loop that takes the cycle's time once (ccomm_now + ccomm_set_time, as
 * the 20-sim target and ccomm-latency do) must make no clock reading in its reads and
 * writes, and exactly one per cycle. */
#define CYCLE_READS 36 /* the thesis' setup simulation: 36 doubles in, 9 out */
#define CYCLE_WRITES 9

/* A Simulink model of 36 ccomm read and 9 ccomm write blocks, stepped as the S-functions
 * and the generated code step them (ccomm_blk.c): each block its own handle; with
 * `step_clock`, each block's call first gives ccomm_blk_step the step's model time. On
 * BUSY_NODE, whose ccommd never sleeps, so writes ring no doorbell. */
static void simulink_model_steps(const char* busy, long steps, int step_clock) {
  ccomm_blk* blocks[CYCLE_READS + CYCLE_WRITES];
  char err[256];
  double y = 0;
  long i;
  int k;
  for (k = 0; k < CYCLE_READS + CYCLE_WRITES; ++k) {
    blocks[k] = k < CYCLE_READS ? ccomm_blk_open(busy, "sleepy_state", 1, 0, err, sizeof err)
                                : ccomm_blk_open(busy, "busy_state", 1, 1, err, sizeof err);
    if (!blocks[k]) {
      fprintf(stderr, "syscount: %s\n", err);
      _exit(2);
    }
  }
  begin(step_clock ? "board-clock:simulink-36r-9w-blocks,step-clock" : "board-clock:simulink-36r-9w-blocks,per-block",
        steps, step_clock ? 1 : CYCLE_READS + CYCLE_WRITES, step_clock ? steps : steps * (CYCLE_READS + CYCLE_WRITES));
  for (i = 0; i < steps; ++i) {
    const double model_time = (double)i * 0.001;
    for (k = 0; k < CYCLE_READS + CYCLE_WRITES; ++k) {
      if (step_clock) ccomm_blk_step(blocks[k], model_time);
      if (k < CYCLE_READS) must(ccomm_blk_read(blocks[k], &y), "ccomm read block");
      else must(ccomm_blk_write(blocks[k], &y), "ccomm write block");
    }
  }
  end();
  for (k = 0; k < CYCLE_READS + CYCLE_WRITES; ++k) ccomm_blk_close(blocks[k]);
}

static void board_clock_workload(const char* sleepy, const char* busy, long n) {
  ccomm_client* quiet = open_or_die(sleepy, CCOMM_OPEN_NO_DOORBELL);
  ccomm_signal fwd = find_or_die(quiet, "sleepy_state");
  ccomm_signal rx = find_or_die(quiet, "busy_state");
  double v = 0;
  ccomm_info info;
  long i;
  int k;

  begin("self-check:getppid", n, 1, n);
  for (i = 0; i < n; ++i) syscall(SYS_getppid);
  end();
  /* The emulation itself: every clock reading must be a system call here. */
  begin("board-clock:self-check,ccomm_now", n, 1, n);
  for (i = 0; i < n; ++i) (void)ccomm_now();
  end();
  must(ccomm_write_double(quiet, fwd, 1.0), "first write");
  begin("board-clock:read,clock-per-call", n, 1, n);
  for (i = 0; i < n; ++i) must(ccomm_read_double(quiet, rx, &v, &info), "read busy_state");
  end();
  begin("board-clock:write,clock-per-call", n, 1, n);
  for (i = 0; i < n; ++i) must(ccomm_write_double(quiet, fwd, (double)i), "write");
  end();
  must(ccomm_set_time(quiet, ccomm_now()), "set_time");
  begin("board-clock:read,cycle-time", n, 0, 0);
  for (i = 0; i < n; ++i) must(ccomm_read_double(quiet, rx, &v, &info), "read busy_state");
  end();
  begin("board-clock:write+flush,cycle-time", n, 0, 0);
  for (i = 0; i < n; ++i) {
    must(ccomm_write_double(quiet, fwd, (double)i), "write");
    must(ccomm_flush(quiet), "flush");
  }
  end();
  /* A whole control cycle: the time once, 36 reads, 9 writes, the flush. */
  long cycles = n / (CYCLE_READS + CYCLE_WRITES) > 100 ? n / (CYCLE_READS + CYCLE_WRITES) : 100;
  begin("board-clock:control-cycle-36r-9w,cycle-time", cycles, 1, cycles);
  for (i = 0; i < cycles; ++i) {
    must(ccomm_set_time(quiet, ccomm_now()), "set_time");
    for (k = 0; k < CYCLE_READS; ++k) must(ccomm_read_double(quiet, rx, &v, &info), "read busy_state");
    for (k = 0; k < CYCLE_WRITES; ++k) must(ccomm_write_double(quiet, fwd, v + k), "write");
    must(ccomm_flush(quiet), "flush");
  }
  end();
  ccomm_close(quiet);
  simulink_model_steps(busy, cycles, 0);
  simulink_model_steps(busy, cycles, 1);
}

/* ---- the parent: the tracer -------------------------------------------------------- */

struct phase {
  char name[64];
  long calls, min_total, total;
  double max_per_call;
  long by_nr[MAX_NR];
};

static const char* syscall_name(long nr) {
  switch (nr) {
    case SYS_futex: return "futex";
    case SYS_getppid: return "getppid";
    case SYS_getpid: return "getpid";
    case SYS_clock_gettime: return "clock_gettime";
#ifdef SYS_clock_gettime64
    case SYS_clock_gettime64: return "clock_gettime64";
#endif
    case SYS_nanosleep: return "nanosleep";
    case SYS_write: return "write";
    default: return NULL;
  }
}

static int read_child(pid_t pid, unsigned long addr, char* buf, size_t len) {
  struct iovec local = {buf, len}, remote = {(void*)addr, len};
  return process_vm_readv(pid, &local, 1, &remote, 1, 0) == (ssize_t)len ? 0 : -1;
}

static int trace(pid_t pid, struct phase* phases, int* nphases) {
  int status;
  struct phase* cur = NULL;
  int paused = 0;
  if (waitpid(pid, &status, 0) < 0 || !WIFSTOPPED(status)) return -1;
  if (ptrace(PTRACE_SETOPTIONS, pid, 0, PTRACE_O_TRACESYSGOOD | PTRACE_O_EXITKILL) != 0)
    return -1;
  int sig = 0;
  for (;;) {
    if (ptrace(PTRACE_SYSCALL, pid, 0, sig) != 0) return -1;
    sig = 0;
    if (waitpid(pid, &status, 0) < 0) return -1;
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
    if (!WIFSTOPPED(status)) continue;
    if (WSTOPSIG(status) != (SIGTRAP | 0x80)) {
      sig = WSTOPSIG(status); /* a real signal: deliver it */
      continue;
    }
    struct ptrace_syscall_info si;
    memset(&si, 0, sizeof si);
    if (ptrace(PTRACE_GET_SYSCALL_INFO, pid, sizeof si, &si) <= 0) return -1;
    if (si.op != PTRACE_SYSCALL_INFO_ENTRY) continue;
    long nr = (long)si.entry.nr;
    if (nr == SYS_write && (int)si.entry.args[0] == -1) { /* a marker */
      char text[160];
      size_t len = si.entry.args[2] < sizeof text - 1 ? si.entry.args[2] : sizeof text - 1;
      if (read_child(pid, si.entry.args[1], text, len) != 0) return -1;
      text[len] = 0;
      if (strncmp(text, "begin ", 6) == 0 && *nphases < MAX_PHASES) {
        cur = &phases[(*nphases)++];
        memset(cur, 0, sizeof *cur);
        if (sscanf(text + 6, "%63s %ld %lf %ld", cur->name, &cur->calls, &cur->max_per_call, &cur->min_total) != 4)
          return -1;
      } else if (strcmp(text, "pause") == 0) {
        paused = 1;
      } else if (strcmp(text, "resume") == 0) {
        paused = 0;
      } else {
        cur = NULL;
      }
      continue;
    }
    if (cur && !paused) {
      cur->total++;
      if (nr >= 0 && nr < MAX_NR) cur->by_nr[nr]++;
    }
  }
}

/* The table as Markdown (docs/performance.md embeds it), when $SYSCOUNT_MARKDOWN names
 * a file. */
static void report_markdown(const struct phase* phases, int n) {
  const char* path = getenv("SYSCOUNT_MARKDOWN");
  if (!path || !*path) return;
  FILE* f = fopen(path, "w");
  if (!f) {
    fprintf(stderr, "syscount: cannot write %s: %s\n", path, strerror(errno));
    return;
  }
  fprintf(f, "| loop (mode, ccommd state) | calls | syscalls | per call | bound | which |\n"
             "|:---|---:|---:|---:|---:|:---|\n");
  for (int i = 0; i < n; ++i) {
    const struct phase* p = &phases[i];
    fprintf(f, "| %s | %ld | %ld | **%.4f** | %s%g | ", p->name, p->calls, p->total,
            p->calls ? (double)p->total / (double)p->calls : 0.0, p->min_total ? "> 0, <= " : "", p->max_per_call);
    for (long nr = 0; nr < MAX_NR; ++nr) {
      if (!p->by_nr[nr]) continue;
      const char* nm = syscall_name(nr);
      if (nm) fprintf(f, "%s %ld ", nm, p->by_nr[nr]);
      else fprintf(f, "#%ld %ld ", nr, p->by_nr[nr]);
    }
    fprintf(f, "|\n");
  }
  fclose(f);
}

/* Phases above their bound; *unwoken: phases whose precondition did not hold (a phase
 * that must wake ccommd made no call: ccommd was never asleep while it ran, e.g. not
 * scheduled on a loaded machine). */
static int report(const struct phase* phases, int n, int* unwoken) {
  report_markdown(phases, n);
  int failed = 0;
  *unwoken = 0;
  printf("%-46s %8s %9s %9s %8s  %s\n", "phase", "calls", "syscalls", "per call", "bound", "result (syscalls by name)");
  for (int i = 0; i < n; ++i) {
    const struct phase* p = &phases[i];
    double per = p->calls ? (double)p->total / (double)p->calls : 0;
    int ok = per <= p->max_per_call + 1e-12 && p->total >= p->min_total;
    failed += per > p->max_per_call + 1e-12;
    *unwoken += p->total < p->min_total;
    char by[256] = "";
    for (long nr = 0; nr < MAX_NR; ++nr) {
      if (!p->by_nr[nr]) continue;
      const char* nm = syscall_name(nr);
      char one[64];
      if (nm) snprintf(one, sizeof one, " %s:%ld", nm, p->by_nr[nr]);
      else snprintf(one, sizeof one, " #%ld:%ld", nr, p->by_nr[nr]);
      strncat(by, one, sizeof by - strlen(by) - 1);
    }
    char bound[32];
    if (p->min_total) snprintf(bound, sizeof bound, "%g>0", p->max_per_call);
    else snprintf(bound, sizeof bound, "%g", p->max_per_call);
    printf("%-46s %8ld %9ld %9.4f %8s  %s%s\n", p->name, p->calls, p->total, per, bound, ok ? "ok" : "FAIL", by);
    if (!ok && p->total < p->min_total)
      printf("  ^ expected at least %ld syscall(s): nothing was woken\n", p->min_total);
  }
  return failed;
}

int main(int argc, char** argv) {
  int board_clock = argc > 1 && strcmp(argv[1], "--board-clock") == 0;
  if (board_clock) {
    ++argv;
    --argc;
  }
  if (argc < 3 || argc > 4 || strcmp(argv[1], "--help") == 0) {
    fprintf(stderr,
            "usage: syscount [--board-clock] SLEEPY_NODE BUSY_NODE [CALLS]\n"
            "Counts the syscalls of libccomm reads, writes and flushes per call (ptrace), in\n"
            "each doorbell mode, against a running ccommd for each node: SLEEPY_NODE with\n"
            "spin_us 0 and signals sleepy_state (forwarded), sleepy_local, busy_state;\n"
            "BUSY_NODE with spin_us >= its heartbeat. CALLS per phase: default 20000.\n"
            "Exit 0: every phase within its bound; 1: some phase above it; 2: set-up error;\n"
            "5: none above, but a phase that must wake ccommd woke nothing (not measured: run again).\n"
            "SYSCOUNT_MARKDOWN=FILE also writes the table to FILE as Markdown.\n"
            "--board-clock: the clock readings of a control cycle instead; run it with\n"
            "LD_PRELOAD=board_clock.so, which makes each clock reading a system call.\n");
    return 2;
  }
  long n = argc == 4 ? strtol(argv[3], NULL, 10) : 20000;
  if (n <= 0) {
    fprintf(stderr, "syscount: CALLS must be a positive number, not '%s'\n", argv[3]);
    return 2;
  }
  fflush(stdout);
  pid_t pid = fork();
  if (pid < 0) {
    perror("syscount: fork");
    return 2;
  }
  if (pid == 0) {
    if (ptrace(PTRACE_TRACEME, 0, NULL, NULL) != 0) {
      perror("syscount: ptrace(TRACEME)");
      _exit(errno == EPERM ? 4 : 2); /* 4: not permitted here, a skip */
    }
    raise(SIGSTOP);
    if (board_clock) board_clock_workload(argv[1], argv[2], n);
    else workload(argv[1], argv[2], n);
    _exit(0);
  }
  static struct phase phases[MAX_PHASES];
  int nphases = 0;
  int rc = trace(pid, phases, &nphases);
  if (rc == 4) return 4;
  if (rc != 0) {
    fprintf(stderr, "syscount: the traced workload failed (status %d%s)\n", rc, rc < 0 ? ", ptrace error" : "");
    return 2;
  }
  int unwoken = 0;
  int failed = report(phases, nphases, &unwoken);
  if (failed) printf("%d phase(s) above their bounds\n", failed);
  if (unwoken) printf("%d phase(s) woke nothing: ccommd was not asleep while they ran\n", unwoken);
  return failed ? 1 : unwoken ? 5 : 0;
}
