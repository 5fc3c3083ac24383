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
  int32_t type;
  uint32_t count;
  uint32_t bytes;
  int is_event;
  int sent_once;
  unsigned char* value;   /* current value, host layout */
  unsigned char* scratch; /* event reads / last event sent */
};

ccomm_blk* ccomm_blk_open(const char* node, const char* signal, int width, int for_write,
                          char* err, size_t err_len) {
  ccomm_blk* b;
  ccomm_signal_desc d;
  int r;
  if (err && err_len) err[0] = '\0';
  if (!signal || !signal[0] || width < 1) {
    if (err) snprintf(err, err_len, "ccomm: block needs a signal name and a width >= 1");
    return NULL;
  }
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

int ccomm_blk_read(ccomm_blk* b, double* y) {
  ccomm_info info;
  uint32_t e;
  int r, k;
  if (!b || !y) return CCOMM_E_INVAL;
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
  }
  for (e = 0; e < b->count; e++) y[e] = get_element(b, e);
  return r;
}

int ccomm_blk_write(ccomm_blk* b, const double* u) {
  uint32_t e;
  int r;
  if (!b || !u) return CCOMM_E_INVAL;
  for (e = 0; e < b->count; e++) set_element(b, e, u[e]);
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

void ccomm_blk_close(ccomm_blk* b) {
  if (!b) return;
  if (b->client) ccomm_close(b->client);
  free(b->value);
  free(b->scratch);
  free(b);
}
