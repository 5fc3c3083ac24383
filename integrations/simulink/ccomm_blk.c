/* SPDX-License-Identifier: Apache-2.0 */
/* ccomm blocks for Simulink (see ccomm_blk.h). ANSI C plus <stdint.h>, so that every
 * compiler Simulink Coder drives can build it. */
#include "ccomm_blk.h"

#include <ccomm/ccomm.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EVENT_DRAIN_LIMIT 1024 /* bounded: a flooding producer cannot stall a step */

struct ccomm_blk {
  ccomm_client* client;
  ccomm_signal id;
  int dtype;          /* the port's CCOMM_BLK_* type */
  int64_t timeout_ns; /* 0: no block timeout */
  int32_t type;
  uint32_t count;
  uint32_t bytes;
  int is_event;
  int sent_once;
  unsigned char* value;   /* current value, host layout */
  unsigned char* scratch; /* event reads / last event sent */
};

/* The step clock (ccomm_blk_step): per thread, since each task of a multitasking model
 * runs its steps on its own thread with its own model time. A compiler without thread-
 * local storage gets a clock reading per block call instead (still correct). */
#if defined(__GNUC__)
#define CCOMM_BLK_STEP_CLOCK 1
static __thread int step_clock_valid;
static __thread double step_model_time;
static __thread int64_t step_now_ns;
#else
#define CCOMM_BLK_STEP_CLOCK 0
#endif

int ccomm_blk_dtype(const char* name) {
  static const struct { const char* name; int id; } types[] = {
      {"double", CCOMM_BLK_DOUBLE}, {"single", CCOMM_BLK_SINGLE}, {"int32", CCOMM_BLK_INT32},
      {"uint32", CCOMM_BLK_UINT32}, {"boolean", CCOMM_BLK_BOOLEAN}};
  size_t i;
  for (i = 0; name && i < sizeof types / sizeof types[0]; i++)
    if (strcmp(name, types[i].name) == 0) return types[i].id;
  return -1;
}

static const char* dtype_name(int dtype) {
  switch (dtype) {
    case CCOMM_BLK_DOUBLE: return "double";
    case CCOMM_BLK_SINGLE: return "single";
    case CCOMM_BLK_INT32: return "int32";
    case CCOMM_BLK_UINT32: return "uint32";
    case CCOMM_BLK_BOOLEAN: return "boolean";
    default: return "?";
  }
}

/* The signal type a non-double port needs; -1 for an unknown port type. */
static int32_t signal_type_for(int dtype) {
  switch (dtype) {
    case CCOMM_BLK_SINGLE: return CCOMM_FLOAT;
    case CCOMM_BLK_INT32: return CCOMM_INT32;
    case CCOMM_BLK_UINT32: return CCOMM_UINT32;
    case CCOMM_BLK_BOOLEAN: return CCOMM_BOOL;
    default: return -1;
  }
}

static const char* signal_type_name(int32_t type) {
  const char* name = ccomm_type_name(type);
  return name ? name : "?";
}

ccomm_blk* ccomm_blk_open(const char* node, const char* signal, int width, int for_write,
                          char* err, size_t err_len) {
  return ccomm_blk_open_typed(node, signal, width, for_write, CCOMM_BLK_DOUBLE, 0.0, err, err_len);
}

ccomm_blk* ccomm_blk_open_typed(const char* node, const char* signal, int width, int for_write,
                                int dtype, double timeout_s, char* err, size_t err_len) {
  ccomm_blk* b;
  ccomm_signal_desc d;
  int r;
  if (err && err_len) err[0] = '\0';
  if (!signal || !signal[0] || width < 1) {
    if (err) snprintf(err, err_len, "ccomm: block needs a signal name and a width >= 1");
    return NULL;
  }
  if (dtype != CCOMM_BLK_DOUBLE && signal_type_for(dtype) < 0) {
    if (err) snprintf(err, err_len, "ccomm: port data type %d is not one of double, single, int32, uint32, boolean", dtype);
    return NULL;
  }
  if (!(timeout_s >= 0.0) || timeout_s > 1e6) {
    if (err) snprintf(err, err_len, "ccomm: timeout %g s must be 0 (none) or a positive number of seconds", timeout_s);
    return NULL;
  }
#if CCOMM_BLK_STEP_CLOCK
  step_clock_valid = 0; /* a new run may start again at the old model time */
#endif
  b = (ccomm_blk*)calloc(1, sizeof *b);
  if (!b) {
    if (err) snprintf(err, err_len, "ccomm: out of memory");
    return NULL;
  }
  r = ccomm_open(node && node[0] ? node : NULL, 0, &b->client);
  if (r != 0) {
    if (err) snprintf(err, err_len, "ccomm: cannot attach to node '%s': %s", node && node[0] ? node : "(default)", ccomm_strerror(r));
    free(b);
    return NULL;
  }
  b->id = ccomm_find(b->client, signal);
  if (b->id < 0 || ccomm_describe(b->client, b->id, &d) != 0) {
    if (err) snprintf(err, err_len, "ccomm: no signal '%s' on node '%s'", signal, ccomm_node_name(b->client));
    ccomm_blk_close(b);
    return NULL;
  }
  if ((int)d.count != width) {
    if (err) snprintf(err, err_len, "ccomm: signal '%s' has %u element(s) but the block width is %d", signal, (unsigned)d.count, width);
    ccomm_blk_close(b);
    return NULL;
  }
  if (for_write && !d.produced_here) {
    if (err) snprintf(err, err_len, "ccomm: signal '%s' is produced by node '%s', not by '%s'", signal, d.producer, ccomm_node_name(b->client));
    ccomm_blk_close(b);
    return NULL;
  }
  if (dtype != CCOMM_BLK_DOUBLE && d.type != signal_type_for(dtype)) {
    if (err) snprintf(err, err_len, "ccomm: signal '%s' is %s; a port of type %s needs signal type %s (or make the port double)",
                      signal, signal_type_name(d.type), dtype_name(dtype), signal_type_name(signal_type_for(dtype)));
    ccomm_blk_close(b);
    return NULL;
  }
  b->dtype = dtype;
  b->timeout_ns = (int64_t)(timeout_s * 1e9);
  b->type = d.type;
  b->count = d.count;
  b->bytes = d.value_bytes;
  b->is_event = d.is_event;
  b->value = (unsigned char*)calloc(1, d.value_bytes);
  b->scratch = (unsigned char*)calloc(1, d.value_bytes);
  if (!b->value || !b->scratch) {
    if (err) snprintf(err, err_len, "ccomm: out of memory");
    ccomm_blk_close(b);
    return NULL;
  }
  return b;
}

static double get_element(const ccomm_blk* b, uint32_t e) {
  const unsigned char* p = b->value;
  switch (b->type) {
    case CCOMM_BOOL: return p[e] ? 1.0 : 0.0;
    case CCOMM_INT32: { int32_t v; memcpy(&v, p + 4 * e, 4); return (double)v; }
    case CCOMM_UINT32: { uint32_t v; memcpy(&v, p + 4 * e, 4); return (double)v; }
    case CCOMM_INT64: { int64_t v; memcpy(&v, p + 8 * e, 8); return (double)v; }
    case CCOMM_FLOAT: { float v; memcpy(&v, p + 4 * e, 4); return (double)v; }
    default: { double v; memcpy(&v, p + 8 * e, 8); return v; }
  }
}

/* Nearest integer, saturated; NaN gives 0: an output never wraps around. */
static double clampr(double v, double lo, double hi) {
  if (v != v) return 0.0;
  v = floor(v + 0.5);
  return v < lo ? lo : (v > hi ? hi : v);
}

static void set_element(ccomm_blk* b, uint32_t e, double v) {
  unsigned char* p = b->value;
  switch (b->type) {
    case CCOMM_BOOL: p[e] = (v != 0.0 && v == v) ? 1 : 0; break;
    case CCOMM_INT32: { int32_t x = (int32_t)clampr(v, -2147483648.0, 2147483647.0); memcpy(p + 4 * e, &x, 4); break; }
    case CCOMM_UINT32: { uint32_t x = (uint32_t)clampr(v, 0.0, 4294967295.0); memcpy(p + 4 * e, &x, 4); break; }
    case CCOMM_INT64: { int64_t x = (int64_t)clampr(v, -9223372036854775808.0, 9223372036854774784.0); memcpy(p + 8 * e, &x, 8); break; }
    case CCOMM_FLOAT: { float x = (float)v; memcpy(p + 4 * e, &x, 4); break; }
    default: memcpy(p + 8 * e, &v, 8); break;
  }
}

/* One sample's read into b->value; returns the block's status. */
static int fetch(ccomm_blk* b) {
  ccomm_info info;
  int r, k;
  if (b->is_event) {
    r = CCOMM_EMPTY;
    for (k = 0; k < EVENT_DRAIN_LIMIT; k++) {
      int s = ccomm_read(b->client, b->id, b->scratch, b->bytes, NULL);
      if (s < 0) {
        r = s;
        break;
      }
      if (s == CCOMM_EMPTY) break;
      memcpy(b->value, b->scratch, b->bytes);
      r = CCOMM_FRESH;
    }
  } else {
    r = ccomm_read(b->client, b->id, b->value, b->bytes, &info);
    if (r == CCOMM_NEVER && !(info.flags & CCOMM_INFO_SAFE_VALUE)) memset(b->value, 0, b->bytes);
    if (r == CCOMM_FRESH && b->timeout_ns > 0 && info.age_ns > b->timeout_ns) r = CCOMM_STALE;
  }
  return r;
}

int ccomm_blk_read(ccomm_blk* b, double* y) {
  uint32_t e;
  int r;
  if (!b || !y) return CCOMM_E_INVAL;
  r = fetch(b);
  for (e = 0; e < b->count; e++) y[e] = get_element(b, e);
  return r;
}

int ccomm_blk_read_port(ccomm_blk* b, void* y) {
  int r;
  if (!b || !y) return CCOMM_E_INVAL;
  if (b->dtype == CCOMM_BLK_DOUBLE) return ccomm_blk_read(b, (double*)y);
  r = fetch(b);
  /* Same type as the signal (checked at open): the port holds the value's bytes. */
  memcpy(y, b->value, b->bytes);
  return r;
}

/* Sends b->value (events: only when it changed). */
static int send(ccomm_blk* b) {
  int r;
  if (b->is_event) {
    if (b->sent_once && memcmp(b->value, b->scratch, b->bytes) == 0) return 0;
    r = ccomm_write(b->client, b->id, b->value, b->bytes);
    if (r == 0) {
      memcpy(b->scratch, b->value, b->bytes);
      b->sent_once = 1;
    }
    return r;
  }
  return ccomm_write(b->client, b->id, b->value, b->bytes);
}

int ccomm_blk_write(ccomm_blk* b, const double* u) {
  uint32_t e;
  if (!b || !u) return CCOMM_E_INVAL;
  for (e = 0; e < b->count; e++) set_element(b, e, u[e]);
  return send(b);
}

int ccomm_blk_write_port(ccomm_blk* b, const void* u) {
  uint32_t e;
  if (!b || !u) return CCOMM_E_INVAL;
  if (b->dtype == CCOMM_BLK_DOUBLE) return ccomm_blk_write(b, (const double*)u);
  memcpy(b->value, u, b->bytes);
  /* A Simulink boolean is 0 or 1 by contract; any other byte still means true. */
  if (b->type == CCOMM_BOOL)
    for (e = 0; e < b->count; e++) b->value[e] = b->value[e] ? 1 : 0;
  return send(b);
}

void ccomm_blk_step(ccomm_blk* b, double model_time) {
  if (!b) return;
#if CCOMM_BLK_STEP_CLOCK
  if (!step_clock_valid || model_time != step_model_time) {
    step_now_ns = ccomm_now();
    step_model_time = model_time;
    step_clock_valid = 1;
  }
  (void)ccomm_set_time(b->client, step_now_ns);
#else
  (void)model_time;
#endif
}

void ccomm_blk_close(ccomm_blk* b) {
  if (!b) return;
  if (b->client) ccomm_close(b->client);
  free(b->value);
  free(b->scratch);
  free(b);
}
