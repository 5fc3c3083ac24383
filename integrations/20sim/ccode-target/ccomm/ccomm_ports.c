/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The ports of submodel %SUBMODEL_NAME% in 20-sim's order (the order of u[] and y[]).
 * ccomm_map.c connects each port to the ccomm signal of the same name.
 */
#include <stddef.h>

const char ccomm_xx_submodel_name[] = "%SUBMODEL_NAME%";
const double ccomm_xx_time_step = %TIME_STEP_SIZE%;
const int ccomm_xx_number_inputs = %NUMBER_INPUTS%;
const int ccomm_xx_number_outputs = %NUMBER_OUTPUTS%;

/* 20-sim writes these lists without a terminator; NULL ends them here. */
const char* const ccomm_xx_input_names[] = {
%IF%%NUMBER_INPUTS%
%INPUT_NAMES2%,
%ENDIF%
    NULL};

const char* const ccomm_xx_output_names[] = {
%IF%%NUMBER_OUTPUTS%
%OUTPUT_NAMES2%,
%ENDIF%
    NULL};
