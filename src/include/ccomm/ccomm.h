/* SPDX-License-Identifier: Apache-2.0 */
/*
 * ccomm C API: read and write named signals of the local node through shared memory.
 *
 * Made for generated controller code (20-sim, Simulink) and hand-written loops:
 *   - ccomm_open / ccomm_find / ccomm_close are start-up and shutdown calls (they
 *     allocate, make syscalls and may fail).
 *   - ccomm_read* and ccomm_write* are real-time safe: lock-free, wait-free in practice
 *     (bounded retries), no allocation, no blocking, no syscall -- except that a write
 *     of a signal forwarded event-driven by ccommd rings a doorbell (one non-blocking
 *     FUTEX_WAKE) when the daemon is asleep, and any write wakes local ccomm_wait()
 *     callers (one FUTEX_WAKE) if there are any. In the Xenomai build (CCOMM_WITH_XENOMAI)
 *     that doorbell is a Cobalt XDDP send, no Linux syscall (docs/design.md, "Xenomai").
 *     Open with CCOMM_OPEN_NO_DOORBELL to make writes syscall-free on plain Linux too;
 *     ccommd then sends at its periodic cycle or heartbeat instead of at once. Measured
 *     per call: docs/performance.md, "System calls per real-time call".
 *   - ccomm_wait blocks and is meant for non-real-time consumers.
 * Every read says whether the value is fresh, stale or was never received.
 * A handle is used by one thread at a time (event cursors live in it); open one handle
 * per thread. Several processes and handles may use the same signals concurrently.
 */
#ifndef CCOMM_CCOMM_H
#define CCOMM_CCOMM_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define CCOMM_API_VERSION 1

#if defined(_WIN32) && defined(CCOMM_BUILDING_DLL)
#define CCOMM_API __declspec(dllexport)
#elif defined(_WIN32)
#define CCOMM_API __declspec(dllimport)
#elif defined(__GNUC__)
#define CCOMM_API __attribute__((visibility("default")))
#else
#define CCOMM_API
#endif

/** Read status (>= 0). */
typedef enum ccomm_status {
  CCOMM_FRESH = 0, /**< value younger than the signal's stale_after_ms */
  CCOMM_STALE = 1, /**< value older than stale_after_ms (or the safe value, see flags) */
  CCOMM_NEVER = 2, /**< nothing received since the node's segment was created */
  CCOMM_EMPTY = 3  /**< event signal: no new event since the last read */
} ccomm_status;

/** Errors (< 0). ccomm_strerror() names them. */
#define CCOMM_E_INVAL (-1)   /**< bad argument: NULL, unknown signal handle */
#define CCOMM_E_NOENT (-2)   /**< no such signal, or no segment: is ccommd running? */
#define CCOMM_E_TYPE (-3)    /**< typed call does not match the signal's type/count, or `len` is not
                                   the signal's value_bytes */
#define CCOMM_E_PERM (-4)    /**< this node is not the signal's producer */
#define CCOMM_E_FULL (-5)    /**< event queue full: ccommd is not forwarding; event not queued */
#define CCOMM_E_BUSY (-6)    /**< writers raced for every slot; retry next cycle */
#define CCOMM_E_SYS (-7)     /**< an OS call failed at open; errno says why */
#define CCOMM_E_VERSION (-8) /**< segment has another layout version than this library */
#define CCOMM_E_RETIRED (-9) /**< ccommd replaced the segment (new config): close and reopen */
#define CCOMM_E_CORRUPT (-10) /**< the value in shared memory failed its check (something wrote
                                   over the segment); nothing returned, counted as `corrupt` */

/** ccomm_info.flags */
#define CCOMM_INFO_SAFE_VALUE 0x1u /**< the value returned is the configured safe value */

/** ccomm_open flags */
#define CCOMM_OPEN_NO_DOORBELL 0x1u /**< writes never make a syscall (see above) */
#define CCOMM_OPEN_BATCH 0x2u       /**< a control step: state writes stay in the handle until
                                         ccomm_flush() stores them all at once and sends them in
                                         one frame per destination (one doorbell per cycle),
                                         whatever other handles do meanwhile; events are queued at
                                         once and leave with the flush */

typedef struct ccomm_client ccomm_client;
/** A signal handle (its id, the position in signals.xml); < 0 is invalid. */
typedef int32_t ccomm_signal;

/** What a read returns besides the value. */
typedef struct ccomm_info {
  int32_t status;          /**< ccomm_status of this read */
  uint32_t flags;          /**< CCOMM_INFO_* */
  uint64_t seq;            /**< producer's sequence number of the value (0 = never) */
  int64_t age_ns;          /**< time since the value reached this node; -1 if never */
  uint64_t source_time_ns; /**< producer's CLOCK_MONOTONIC when it wrote the value */
  uint64_t lost;           /**< values/events of this signal known lost so far (this handle's
                                overruns plus gaps seen by ccommd) */
} ccomm_info;

typedef enum ccomm_type {
  CCOMM_BOOL = 1, CCOMM_INT32 = 2, CCOMM_UINT32 = 3, CCOMM_INT64 = 4, CCOMM_FLOAT = 5, CCOMM_DOUBLE = 6
} ccomm_type;
/** The name of a ccomm_type as signals.xml writes it (bool, int32, uint32, int64, float,
 *  double); NULL for another value. Tools take type names from here. */
CCOMM_API const char* ccomm_type_name(int32_t type);
/** Bytes of one element of a ccomm_type (bool: 1); 0 for another value. */
CCOMM_API uint32_t ccomm_type_size(int32_t type);
/** Reads one element of a value of type `type` from `text` exactly as signals.xml reads a
 *  safe_value: bool true/false/1/0; integers in decimal or 0x hex, '-' only for signed
 *  types, no '+'; float and double in C syntax, inf and nan included. Writes
 *  ccomm_type_size(type) bytes to `out`. Returns 0, CCOMM_E_INVAL (not a number of that
 *  type, or an unknown type) or CCOMM_E_TYPE (a number that does not fit the type: a float
 *  that would become inf or 0 is refused, never rounded). For tools (ccomm pub), not [rt]. */
CCOMM_API int ccomm_parse_element(int32_t type, const char* text, void* out);
/** The ccomm_type called `name` ("double"), or CCOMM_E_INVAL. */
CCOMM_API int ccomm_type_from_name(const char* name);

/*
 * Growable structs. ccomm_signal_desc, ccomm_signal_stats, ccomm_peer_stats,
 * ccomm_peer_clock, ccomm_clock_state, ccomm_production_age and the ccomm_view_* structs gain fields only at their end. The calls that fill them take the
 * caller's sizeof (the *_sized entry points; the plain names below are macros passing
 * sizeof(*out)): the library fills that many bytes and zeroes any it has no field for, so
 * a program keeps working against a newer library (and a newer one against an older).
 * The plain symbols stay for programs built before: ccomm_get_signal_stats fills the
 * 0.1.0 layout (80 bytes), ccomm_describe the layout without `forwarded`, the others the
 * layout of this header, which they had then.
 * ccomm_info, ccomm_history_cursor and ccomm_history_info are fixed: the real-time calls
 * take no size. CCOMM_E_INVAL if `size` is smaller than the first layout the *_sized
 * calls had (a struct of this header without its appended members).
 */

/** Static description of a signal. */
typedef struct ccomm_signal_desc {
  const char* name;        /**< points into the segment; valid until ccomm_close */
  int32_t type;            /**< ccomm_type */
  uint32_t count;          /**< array length (1 = scalar) */
  uint32_t value_bytes;    /**< count * element size: the length read/write expect */
  int32_t is_event;        /**< 1 = event (queued), 0 = state (last value wins) */
  int32_t produced_here;   /**< 1 if this node may write it */
  uint32_t stale_after_ms; /**< 0 = never stale */
  const char* producer;    /**< producer node name */
  int32_t consumed_here;   /**< 1 if produced elsewhere and delivered to this node */
  int32_t forwarded;       /**< 1 if produced here and consumed by another node (ccommd sends
                                it); 0 for a signal only this node uses. Appended */
} ccomm_signal_desc;

/**
 * Attaches to the shared-memory segment of `node` (NULL: $CCOMM_NODE, else the
 * hostname). The segment is created by ccommd; returns CCOMM_E_NOENT if it does not
 * exist. Not real-time safe.
 */
CCOMM_API int ccomm_open(const char* node, uint32_t flags, ccomm_client** out);
/** Detaches; the handle is freed. Not real-time safe. */
CCOMM_API void ccomm_close(ccomm_client* c);
/** Name of an error or status code. */
CCOMM_API const char* ccomm_strerror(int code);

/** Signal handle by name, or CCOMM_E_NOENT. Do this at start-up, not in the loop. */
CCOMM_API ccomm_signal ccomm_find(ccomm_client* c, const char* name);
/** Number of signals in the system (ids are 0..n-1). */
CCOMM_API int ccomm_signal_count(const ccomm_client* c);
/** Describes a signal; CCOMM_E_INVAL for a bad handle. */
CCOMM_API int ccomm_describe(const ccomm_client* c, ccomm_signal s, ccomm_signal_desc* out);
CCOMM_API int ccomm_describe_sized(const ccomm_client* c, ccomm_signal s, ccomm_signal_desc* out, size_t size);
#define ccomm_describe(c, s, out) ccomm_describe_sized((c), (s), (out), sizeof(*(out)))
/** Name of the node this handle is attached to. */
CCOMM_API const char* ccomm_node_name(const ccomm_client* c);

/**
 * Reads a signal. `len` must equal the signal's value_bytes (else CCOMM_E_TYPE). State signals: copies the
 * last value (or the safe value when stale, if configured). Event signals: pops the
 * next event for this handle, or returns CCOMM_EMPTY. Returns a ccomm_status (>= 0) or
 * an error (< 0); `info` may be NULL. Real-time safe.
 */
CCOMM_API int ccomm_read(ccomm_client* c, ccomm_signal s, void* value, size_t len, ccomm_info* info);
/**
 * Writes a signal produced by this node; `len` must equal value_bytes (else CCOMM_E_TYPE). Returns 0 or an
 * error; nothing is half-written. Real-time safe (see the doorbell note above).
 */
CCOMM_API int ccomm_write(ccomm_client* c, ccomm_signal s, const void* value, size_t len);

/**
 * With CCOMM_OPEN_BATCH: stores every state value written since the last flush and hands
 * them to ccommd at once, so a control step's outputs travel in one frame (reads see
 * them from the flush on). Call it at the end of each cycle. Returns 0, or CCOMM_E_BUSY if
 * a value could not be stored. Without the flag it does nothing. Real-time safe (same
 * doorbell note).
 */
CCOMM_API int ccomm_flush(ccomm_client* c);

/* Typed scalar shortcuts: CCOMM_E_TYPE if the signal is not a scalar of that type. */
CCOMM_API int ccomm_read_double(ccomm_client* c, ccomm_signal s, double* v, ccomm_info* info);
CCOMM_API int ccomm_write_double(ccomm_client* c, ccomm_signal s, double v);
CCOMM_API int ccomm_read_float(ccomm_client* c, ccomm_signal s, float* v, ccomm_info* info);
CCOMM_API int ccomm_write_float(ccomm_client* c, ccomm_signal s, float v);
CCOMM_API int ccomm_read_int32(ccomm_client* c, ccomm_signal s, int32_t* v, ccomm_info* info);
CCOMM_API int ccomm_write_int32(ccomm_client* c, ccomm_signal s, int32_t v);
CCOMM_API int ccomm_read_uint32(ccomm_client* c, ccomm_signal s, uint32_t* v, ccomm_info* info);
CCOMM_API int ccomm_write_uint32(ccomm_client* c, ccomm_signal s, uint32_t v);
CCOMM_API int ccomm_read_int64(ccomm_client* c, ccomm_signal s, int64_t* v, ccomm_info* info);
CCOMM_API int ccomm_write_int64(ccomm_client* c, ccomm_signal s, int64_t v);
CCOMM_API int ccomm_read_bool(ccomm_client* c, ccomm_signal s, int* v, ccomm_info* info);
CCOMM_API int ccomm_write_bool(ccomm_client* c, ccomm_signal s, int v);

/**
 * Cycle time. A control loop that reads and writes several signals per cycle can take
 * the time once per cycle: after ccomm_set_time(c, t_ns), this handle's reads judge
 * freshness and age against t_ns, and its writes are stamped t_ns (the cycle's sample
 * instant), instead of reading CLOCK_MONOTONIC in every call, until the next
 * ccomm_set_time(). A value that arrived after t_ns reads as fresh with age 0.
 * t_ns = 0 returns to one clock reading per call (the default). Real-time safe; no
 * syscall. Returns 0, or CCOMM_E_INVAL for a NULL handle or a negative time.
 */
CCOMM_API int ccomm_set_time(ccomm_client* c, int64_t t_ns);

/** CLOCK_MONOTONIC in nanoseconds: the clock of every ccomm time stamp and age. */
CCOMM_API int64_t ccomm_now(void);

/**
 * Real-time set-up of the calling thread, for an application's own control loop: the one
 * ccommd and ccomm's programs use, one implementation per platform, in this order: the
 * CPU `cpu` (< 0: leave it), the memory lock (`lock_memory` nonzero: current and future
 * memory), the priority (`fifo_priority` 1..99: SCHED_FIFO; 0: leave it). POSIX:
 * pthread_setaffinity_np, mlockall(MCL_CURRENT | MCL_FUTURE), pthread_setschedparam;
 * Windows: SetThreadAffinityMask, a larger working set, THREAD_PRIORITY_TIME_CRITICAL.
 * `errors` (NULL: not wanted) gets each part's result in that order: 0 (also for a part not
 * asked for) or a negative errno (-EPERM: not permitted; root, or CAP_SYS_NICE and
 * CAP_IPC_LOCK, or limits.conf's rtprio and memlock). Returns 0 if every part asked for
 * was done, else CCOMM_E_SYS: the parts that could be done are, and the loop may run
 * without the others. Not real-time: call it once, before the loop.
 */
CCOMM_API int ccomm_realtime_setup(int32_t cpu, int32_t lock_memory, int32_t fifo_priority, int32_t errors[3]);

/**
 * Sleeps until ccomm_now() reaches `deadline_ns` (absolute: a periodic loop adds its period
 * to the deadline and keeps its rate whatever a cycle took; a deadline already past returns
 * at once). Returns 0 at the deadline, 1 if a signal handler ran first (check the stop flag,
 * then sleep again), CCOMM_E_INVAL for a negative deadline. A system call: the loop's one
 * wait between cycles, not for inside one.
 */
CCOMM_API int ccomm_sleep_until(int64_t deadline_ns);

/**
 * Blocks until any signal of this node has changed (a value arrived from the network or
 * was written locally) since the previous ccomm_wait() on this handle returned (or since
 * ccomm_open), or `timeout_ms` passes (< 0: forever; 0: just look). Returns 1 if
 * something changed, 0 on timeout, CCOMM_E_RETIRED as soon as ccommd replaces the
 * segment (new configuration: reopen), CCOMM_E_INVAL for a NULL handle. A change between
 * the caller's reads and this call is never missed: it returns at once. Costs one look at every signal of the node; for
 * non-real-time consumers (a control loop just reads each cycle).
 */
CCOMM_API int ccomm_wait(ccomm_client* c, int timeout_ms);

/** 1 if ccommd updated its heartbeat in the segment within the last second, else 0. */
CCOMM_API int ccomm_daemon_alive(const ccomm_client* c);

/*
 * History tap (signals.xml: <node history="N">): every value of a state signal this
 * node receives, in order, not only the latest. ccommd keeps the last N values of each
 * received state in a ring; a reader with its own cursor gets each value once, or
 * learns exactly how many it missed by falling more than N behind (never silently).
 * For recorders and loggers: lock-free, no syscall, no allocation, never blocks.
 */
typedef struct ccomm_history_cursor {
  uint64_t next;        /**< position of the next value to read */
  uint64_t overrun;     /**< values this cursor missed (it fell more than N behind) */
  uint64_t internal[3]; /**< the reader's bookkeeping: set by ccomm_history_start, leave alone */
} ccomm_history_cursor;

/** What ccomm_history_read returns besides the value. */
typedef struct ccomm_history_info {
  uint64_t seq;             /**< producer's sequence number of the value */
  uint64_t source_time_ns;  /**< producer's CLOCK_MONOTONIC when it wrote the value */
  uint64_t receive_time_ns; /**< this node's CLOCK_MONOTONIC when ccommd stored it */
  uint64_t overrun;         /**< the cursor's overrun count (see above) */
  uint64_t lost;            /**< gaps in the producer's sequence seen by ccommd: values that
                                 never reached this node */
} ccomm_history_info;

/** N of signal `s` (> 0), 0 if it has no history ring (an event, not received here, or
    the node has no history=), CCOMM_E_INVAL for a bad handle or signal. */
CCOMM_API int ccomm_history_depth(const ccomm_client* c, ccomm_signal s);
/** Starts `cur` `back` values before the next one to arrive: 0 = only new values, 1 = the
    newest value kept too, N (or more) = every value kept. Returns 0, CCOMM_E_NOENT if `s`
    has no history ring, CCOMM_E_INVAL. */
CCOMM_API int ccomm_history_start(const ccomm_client* c, ccomm_signal s, uint32_t back,
                                  ccomm_history_cursor* cur);
/** Next value at `cur`: CCOMM_FRESH with the value (`len` = value_bytes) and `info`,
    CCOMM_EMPTY when there is none yet (`info` has only overrun and lost), CCOMM_E_CORRUPT
    (a damaged copy, skipped and counted in overrun), or CCOMM_E_NOENT / E_TYPE / E_INVAL /
    E_RETIRED as ccomm_read. `info` may be NULL. */
CCOMM_API int ccomm_history_read(ccomm_client* c, ccomm_signal s, ccomm_history_cursor* cur, void* value,
                                 size_t len, ccomm_history_info* info);

/*
 * Introspection: the counters ccommd and the clients keep for this node (what
 * `ccomm stats` shows). For tools and monitoring; not real-time calls (they read many
 * words), but they never block and never allocate. Counters only grow.
 */

/** Counters of one signal on this node. */
typedef struct ccomm_signal_stats {
  uint64_t writes;            /**< local writes accepted */
  uint64_t write_errors;      /**< local writes refused (full, busy) */
  uint64_t tx;                /**< values ccommd sent */
  uint64_t coalesced;         /**< values replaced by a newer one before ccommd sent them */
  uint64_t rx;                /**< values ccommd received */
  uint64_t lost;              /**< gaps in the producer's sequence seen by ccommd */
  uint64_t overflow;          /**< events readers lost to ring overrun */
  uint64_t stale_transitions; /**< fresh -> stale seen by ccommd's supervision */
  uint64_t corrupt;           /**< copies that failed their check (any reader, ccommd included) */
  int64_t last_rx_age_ns;     /**< age of the last received value; -1 if none */
  int32_t stale;              /**< consumed here with stale_after_ms, and older than that (or never) */
  uint64_t fragments_refused; /**< values above one frame: fragments refused as bad input (duplicate, overlap...) */
  uint64_t values_incomplete; /**< values above one frame: values given up for a missing fragment (also in `lost`) */
} ccomm_signal_stats;
/** Fills `out`; CCOMM_E_INVAL for a bad handle or signal. */
CCOMM_API int ccomm_get_signal_stats(const ccomm_client* c, ccomm_signal s, ccomm_signal_stats* out);
CCOMM_API int ccomm_get_signal_stats_sized(const ccomm_client* c, ccomm_signal s, ccomm_signal_stats* out,
                                           size_t size);
#define ccomm_get_signal_stats(c, s, out) ccomm_get_signal_stats_sized((c), (s), (out), sizeof(*(out)))

/** Number of nodes in the system (node indexes are 0..n-1, in signals.xml order). */
CCOMM_API int ccomm_node_count(const ccomm_client* c);

/** What this node's ccommd knows of node `node` (frames from and to it). */
typedef struct ccomm_peer_stats {
  const char* name;           /**< points into the segment; valid until ccomm_close */
  int32_t is_self;            /**< 1 for the node this handle is attached to (counters 0) */
  int32_t alive;              /**< 1 while its heartbeats arrive within peer_timeout_ms */
  uint64_t frames_rx, frames_tx;
  uint64_t frames_lost;       /**< gaps in its frame sequence */
  uint64_t frames_reordered;  /**< frames older than expected (duplicates, reordering) */
  uint64_t heartbeats_rx;
  uint64_t down_transitions;  /**< alive -> lost */
  int64_t last_rx_age_ns;     /**< -1 if nothing was received from it */
} ccomm_peer_stats;
/** Fills `out`; CCOMM_E_INVAL for a bad handle or node index. */
CCOMM_API int ccomm_get_peer_stats(const ccomm_client* c, int node, ccomm_peer_stats* out);
CCOMM_API int ccomm_get_peer_stats_sized(const ccomm_client* c, int node, ccomm_peer_stats* out, size_t size);
#define ccomm_get_peer_stats(c, node, out) ccomm_get_peer_stats_sized((c), (node), (out), sizeof(*(out)))

/**
 * A peer's clock as this node's ccommd bounds it from the peer's frames alone (no clock
 * synchronisation needed; docs/design.md, "Time"). Each frame's arrival minus its send
 * time (the peer's CLOCK_MONOTONIC) is this node's clock minus the peer's plus the
 * frame's delay; the smallest over the last 2-4 s (`offset_floor_ns`) stands for the
 * path's fastest delay, and whatever a frame took beyond it is its queueing delay. A
 * value's age (ccomm_info.age_ns) includes its frame's queueing delay, so a frame that
 * waited seconds in a queue (a stopped ccommd, a full socket) does not read as fresh.
 * The age is then exact to within the fastest one-way delay of the window (too young by
 * at most that) plus the clocks' drift over the window (at most rho * 4 s, rho the
 * boards' relative frequency error).
 */
typedef struct ccomm_peer_clock {
  int32_t known;                /**< 1 once a frame arrived from it (the rest is valid) */
  int32_t reserved;             /**< 0 */
  int64_t offset_floor_ns;      /**< min(arrival - send time) over the window */
  uint64_t queue_delay_ns;      /**< the last frame's delay beyond that floor */
  uint64_t queue_delay_max_ns;  /**< the largest such delay since ccommd created the segment */
  uint64_t frames_delayed;      /**< frames held >= 10 ms beyond the floor (their values aged by it) */
} ccomm_peer_clock;
/** Fills `out` for node `node` (known = 0 for this node itself); CCOMM_E_INVAL for a bad
 *  handle or node index. Growable (see "Growable structs"). */
CCOMM_API int ccomm_get_peer_clock_sized(const ccomm_client* c, int node, ccomm_peer_clock* out, size_t size);
#define ccomm_get_peer_clock(c, node, out) ccomm_get_peer_clock_sized((c), (node), (out), sizeof(*(out)))

/** This board's clock synchronisation, as ccommd reads it from linuxptp's ptp4l once a second. */
typedef enum ccomm_clock_state_code {
  CCOMM_CLOCK_NONE = 0,    /**< no ptp4l answers (none running, or ccommd --ptp-socket none): ages are local */
  CCOMM_CLOCK_SYNCING = 1, /**< ptp4l runs; its port is not (yet) a slave within the threshold, nor grandmaster */
  CCOMM_CLOCK_SYNCED = 2,  /**< slave with |offset from master| <= 1 ms, or the grandmaster itself */
  CCOMM_CLOCK_LOST = 3     /**< ptp4l answered before and stopped (killed, hung), or its port is faulty */
} ccomm_clock_state_code;
typedef struct ccomm_clock_state {
  int32_t state;            /**< ccomm_clock_state_code; CCOMM_CLOCK_NONE also when ccommd never ran */
  int32_t port_state;       /**< IEEE 1588 portState of ptp4l's port (9 slave, 6 master, 8 uncalibrated,
                                 4 listening, 2 faulty...); 0 unknown */
  int64_t offset_ns;        /**< ptp4l's last offset from its master (TIME_STATUS_NP master_offset) */
  int64_t path_delay_ns;    /**< its peer mean path delay (P2P delay mechanism; 0 with E2E) */
} ccomm_clock_state;
/** Fills `out`; CCOMM_E_INVAL for a bad handle. Growable (see "Growable structs"). */
CCOMM_API int ccomm_get_clock_state_sized(const ccomm_client* c, ccomm_clock_state* out, size_t size);
#define ccomm_get_clock_state(c, out) ccomm_get_clock_state_sized((c), (out), sizeof(*(out)))
/** "none", "syncing", "synced", "lost" (or "?"). */
CCOMM_API const char* ccomm_clock_state_name(int state);

/**
 * Daemon-wide counter `index` (0, 1, ... until CCOMM_E_INVAL): its name (e.g.
 * "frames_bad", see ccomm(1)) and value. `name` or `value` may be NULL.
 */
CCOMM_API int ccomm_get_daemon_counter(const ccomm_client* c, int index, const char** name, uint64_t* value);
/** How many times a ccommd created or re-adopted this node's segment (1 = first start). */
CCOMM_API uint32_t ccomm_daemon_generation(const ccomm_client* c);

/*
 * System view: what this node's ccommd learned from every node's summary (uptime, the
 * peers it hears, its counters, per signal it produces or consumes: rate, loss,
 * staleness), sent between the ccommd's at most once per 100 ms each (`<network
 * summary_ms>`, docs/protocol.md "Node summary"). What `ccomm stats --all` shows. Not
 * real-time calls; they never block and never allocate after ccomm_view_open.
 */
typedef struct ccomm_view ccomm_view;

/** ccomm_view_signal.role */
#define CCOMM_ROLE_PRODUCER 1
#define CCOMM_ROLE_CONSUMER 2

/**
 * Maps the view of the node `c` is attached to (read-only). `c` must stay open while the
 * view is used. CCOMM_E_NOENT: no view (no ccommd running, or one older than the view);
 * CCOMM_E_VERSION: a view of another layout.
 */
CCOMM_API int ccomm_view_open(const ccomm_client* c, ccomm_view** out);
CCOMM_API void ccomm_view_close(ccomm_view* v);

/** One node, as its newest summary describes it. */
typedef struct ccomm_view_node {
  const char* name;        /**< valid until ccomm_close of the client */
  int32_t is_self;         /**< the node this view belongs to (its own summary) */
  int32_t reported;        /**< 1 once a summary of it arrived (else only name is set) */
  int32_t alive;           /**< its last summary is younger than `timeout_ns` */
  int64_t age_ns;          /**< since its last summary arrived; -1 if never */
  int64_t timeout_ns;      /**< three of its summary intervals, at least peer_timeout_ms */
  uint64_t uptime_ns;      /**< its ccommd's uptime when it sent that summary */
  uint64_t peers_alive;    /**< bit i set: it hears node i */
  uint64_t frames_rx, frames_tx, frames_bad;
  uint64_t frames_lost;    /**< gaps in its peers' frame sequences, summed */
  uint64_t socket_drops;
  uint32_t cycle_ms;       /**< its time to send its whole summary once */
  uint64_t summaries;      /**< summary parts of it applied here */
  /* Its clock, as of that summary (docs/design.md, "Time"); fields added at the end. */
  int32_t clock_state;     /**< ccomm_clock_state_code of that node */
  int32_t reserved;        /**< 0 */
  int64_t clock_error_ns;  /**< bound on its clock's offset from the PTP grandmaster; -1: none (not synced) */
} ccomm_view_node;
/**
 * Production age: how long ago the producer wrote a value, on the common time base of the
 * boards' PTP-synchronised clocks, with a bound on its error (docs/design.md, "Time").
 * ccomm_info.age_ns is local (since the value reached this node); this is end to end.
 */
typedef enum ccomm_production_age_code {
  CCOMM_PAGE_SYNCED = 0,        /**< both clocks synced: age_ns is within +/- error_ns */
  CCOMM_PAGE_SAME_NODE = 1,     /**< produced on this node: one clock, age_ns exact (error_ns 0) */
  CCOMM_PAGE_NEVER = 2,         /**< the read returned no value (info seq 0): unknown */
  CCOMM_PAGE_LOCAL_UNSYNCED = 3,/**< this board's clock is not synced: unknown */
  CCOMM_PAGE_PRODUCER_UNSYNCED = 4, /**< the producer's clock is not synced: unknown */
  CCOMM_PAGE_NO_SUMMARY = 5     /**< no current summary of the producer (summary_ms 0, not heard,
                                     busy record): its clock is unknown, so is the age */
} ccomm_production_age_code;
typedef struct ccomm_production_age {
  int32_t code;      /**< ccomm_production_age_code */
  int32_t known;     /**< 1 for CCOMM_PAGE_SYNCED and _SAME_NODE (age_ns valid), else 0 */
  int64_t age_ns;    /**< since the producer wrote the value, as of this call; -1 when unknown */
  int64_t error_ns;  /**< |true age - age_ns| <= error_ns (the two clocks' bounds plus 2 us for reading
                          their two offsets, 1 us each); -1 when unknown: never an age presented as
                          exact when it is not */
  int64_t production_time_ns; /**< when the producer wrote the value, on the common time base: this
                                   board's CLOCK_REALTIME in ns since the epoch (within +/- error_ns);
                                   the DDS source timestamp and the recorder's publish time. -1 when
                                   unknown. Added in 0.3 (growable: older callers do not get it) */
} ccomm_production_age;
/**
 * The production age of the value a read of signal `s` returned (`info`, as ccomm_read*
 * filled it), as of now. Needs the view (ccomm_view_open, once, at start-up: not a
 * real-time call); this call itself is bounded and allocation-free: two seqlock reads of
 * view records (no waiting: a record being rewritten gives CCOMM_PAGE_NO_SUMMARY) and
 * one CLOCK_REALTIME reading. 0, or CCOMM_E_INVAL (bad view, signal or info). Growable.
 */
CCOMM_API int ccomm_view_production_age_sized(const ccomm_view* v, ccomm_signal s, const ccomm_info* info,
                                              ccomm_production_age* out, size_t size);
#define ccomm_view_production_age(v, s, info, out) \
  ccomm_view_production_age_sized((v), (s), (info), (out), sizeof(*(out)))
/** "synced", "same_node", "never", "local_unsynced", "producer_unsynced", "no_summary"
 *  (or "?"): a ccomm_production_age_code as tools print and record it. */
CCOMM_API const char* ccomm_production_age_name(int code);

/** Fills `out`; CCOMM_E_INVAL for a bad handle or node index, CCOMM_E_BUSY if the record
 *  was being rewritten throughout ~50 ms of waiting (ccommd stopped mid-rewrite). The view
 *  calls may sleep: they are for monitoring tools, not for a control loop. */
CCOMM_API int ccomm_view_get_node(const ccomm_view* v, int node, ccomm_view_node* out);
CCOMM_API int ccomm_view_get_node_sized(const ccomm_view* v, int node, ccomm_view_node* out, size_t size);
#define ccomm_view_get_node(v, node, out) ccomm_view_get_node_sized((v), (node), (out), sizeof(*(out)))

/** One signal as node `node` reports it. */
typedef struct ccomm_view_signal {
  const char* name;   /**< valid until ccomm_close of the client */
  int32_t role;       /**< CCOMM_ROLE_PRODUCER or CCOMM_ROLE_CONSUMER at that node */
  int32_t stale;      /**< consumer: older than its stale_after_ms (or never received);
                           also 1 for any signal of a node that is not alive (report outdated) */
  double rate;        /**< values per second over the node's last summary cycle (producer:
                           writes; consumer: values received) */
  uint64_t lost;      /**< consumer: sequence gaps; producer: writes refused */
  int64_t age_ns;     /**< since the last value (consumer: arrived; producer: written), as the
                           node measured it when it sent its summary (see the node's age_ns);
                           -1 if never */
} ccomm_view_signal;
/** Fills `out`; CCOMM_E_NOENT if that node does not report (produce or consume) the signal
 *  or no summary of it arrived yet; CCOMM_E_INVAL for a bad handle, node or signal. */
CCOMM_API int ccomm_view_get_signal(const ccomm_view* v, int node, ccomm_signal s, ccomm_view_signal* out);
CCOMM_API int ccomm_view_get_signal_sized(const ccomm_view* v, int node, ccomm_signal s, ccomm_view_signal* out,
                                          size_t size);
#define ccomm_view_get_signal(v, node, s, out) ccomm_view_get_signal_sized((v), (node), (s), (out), sizeof(*(out)))

/** Summary traffic of this node's ccommd (counters only grow). */
typedef struct ccomm_view_counters {
  uint64_t summaries_tx, summaries_rx;
  uint64_t summaries_refused;  /**< unknown sender or signal, wrong source, config or destination */
  uint64_t summaries_old;      /**< not newer than the sender's last one (duplicates) */
  uint64_t summaries_send_errors;
  uint32_t summary_ms;         /**< this node's <network summary_ms> (0: it sends none) */
} ccomm_view_counters;
CCOMM_API int ccomm_view_get_counters(const ccomm_view* v, ccomm_view_counters* out);
CCOMM_API int ccomm_view_get_counters_sized(const ccomm_view* v, ccomm_view_counters* out, size_t size);
#define ccomm_view_get_counters(v, out) ccomm_view_get_counters_sized((v), (out), sizeof(*(out)))

#ifdef __cplusplus
}
#endif
#endif /* CCOMM_CCOMM_H */
