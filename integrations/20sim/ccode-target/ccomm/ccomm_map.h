/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Ports to ccomm signals for submodel %SUBMODEL_NAME%, between ccomm_main.c (the periodic
 * task) and ccomm_map.c (the mapping, the reads and writes, the value conversion).
 * The port lists come from ccomm_ports.c.
 */
#ifndef CCOMM_XX_MAP_H
#define CCOMM_XX_MAP_H

#include <ccomm/ccomm.h>
#include <stdint.h>

#include "xxtypes.h"

/* ccomm_ports.c */
extern const char ccomm_xx_submodel_name[];
extern const double ccomm_xx_time_step;
extern const int ccomm_xx_number_inputs;
extern const int ccomm_xx_number_outputs;
extern const char* const ccomm_xx_input_names[];
extern const char* const ccomm_xx_output_names[];

#define CCOMM_XX_MAX_MAPS 256

/* How ports are connected (the task's --map, --prefix, --ignore-unmapped). */
typedef struct {
  const char* prefix;                          /* port X connects to signal PX */
  const char* map_port[CCOMM_XX_MAX_MAPS];     /* port map_port[i] connects to */
  const char* map_signal[CCOMM_XX_MAX_MAPS];   /* signal map_signal[i] */
  int n_maps;
  int ignore_unmapped; /* a port without a signal stays unconnected instead of failing */
} ccomm_xx_map_options;

/* Counted by ccomm_xx_read_inputs and ccomm_xx_write_outputs. */
typedef struct {
  uint64_t stale_cycles; /* periods in which some input was not fresh */
  uint64_t read_errors, write_errors;
} ccomm_xx_io_counts;

/* Connects every port; prints every problem, returns 0 if any port cannot be used. */
int ccomm_xx_map_ports(ccomm_client* c, const ccomm_xx_map_options* o);

/* One period's reads into u[] and writes from y[]. Return 0, or a ccomm error that ends
 * the task (segment retired). */
int ccomm_xx_read_inputs(ccomm_client* c, XXDouble* u, ccomm_xx_io_counts* n);
int ccomm_xx_write_outputs(ccomm_client* c, const XXDouble* y, ccomm_xx_io_counts* n);

#endif
