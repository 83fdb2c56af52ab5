/* Test driver for the header `auvrl export --format c` writes (tests/tools/test_policy_export):
 * a plain C99 program built with `cc -std=c99 -Wall -Wextra -pedantic -Werror -I DIR
 * policy_driver.c -lm`, DIR holding auvrl_policy.h. Files are raw little-endian arrays.
 *
 *   policy_driver act STATES ACTIONS   float32 states (AUVRL_POLICY_STATE_DIM each) ->
 *                                      float32 actions (AUVRL_POLICY_NUM_ACTIONS each)
 *   policy_driver state NAV STATES     float64 records of 12 + 2 n + 3 values (position NED,
 *                                      roll/pitch/yaw, body velocity, body rates, realised
 *                                      thrust x n, previous action x n, goal NED) -> float32
 *                                      states (auvrl_policy_build_state)
 *   policy_driver integrate NAV GOALS  float64 records of 6 values (position NED, way-point
 *                                      NED), one control step each, from a zero offset ->
 *                                      float64 moved way-points (auvrl_policy_integrate_goal)
 *   policy_driver filter NAV POSITIONS float64 records of 9 values (position NED, roll/pitch/
 *                                      yaw, body velocity), one control step each, from a
 *                                      zeroed filter -> float64 estimated positions
 *                                      (auvrl_policy_filter_position)
 *   policy_driver faults RECORDS OUT   float32 records of a state and an action
 *                                      (AUVRL_POLICY_STATE_DIM + AUVRL_POLICY_NUM_ACTIONS), one
 *                                      control step each, from a zeroed struct -> float32
 *                                      actions (auvrl_policy_accommodate_faults)
 *   policy_driver params PARAMS        auvrl_policy_params as float32
 */
#include <stdio.h>
#include <string.h>

#include "auvrl_policy.h"

#define NAV_RECORD (12 + 2 * AUVRL_POLICY_NUM_THRUSTERS + 3)

static int act(FILE *in, FILE *out) {
  float state[AUVRL_POLICY_STATE_DIM], action[AUVRL_POLICY_NUM_ACTIONS];
  while (fread(state, sizeof state, 1, in) == 1) {
    auvrl_policy_act(state, action);
    if (fwrite(action, sizeof action, 1, out) != 1) return 1;
  }
  return 0;
}

static int build_state(FILE *in, FILE *out) {
  double r[NAV_RECORD];
  while (fread(r, sizeof r, 1, in) == 1) {
    auvrl_nav nav;
    float previous[AUVRL_POLICY_NUM_THRUSTERS], state[AUVRL_POLICY_STATE_DIM];
    int i;
    for (i = 0; i < 3; ++i) {
      nav.position_ned_m[i] = r[i];
      nav.euler_rpy_rad[i] = r[3 + i];
      nav.velocity_body_mps[i] = r[6 + i];
      nav.angular_rate_body_rad_s[i] = r[9 + i];
    }
    for (i = 0; i < AUVRL_POLICY_NUM_THRUSTERS; ++i) {
      nav.thrust_realised_n[i] = r[12 + i];
      previous[i] = (float)r[12 + AUVRL_POLICY_NUM_THRUSTERS + i];
    }
    auvrl_policy_build_state(&nav, r + 12 + 2 * AUVRL_POLICY_NUM_THRUSTERS, previous, state);
    if (fwrite(state, sizeof state, 1, out) != 1) return 1;
  }
  return 0;
}

static int integrate(FILE *in, FILE *out) {
  double r[6], offset_ned_m[3] = {0.0, 0.0, 0.0}, moved_goal_ned_m[3];
  auvrl_nav nav;
  memset(&nav, 0, sizeof nav);
  while (fread(r, sizeof r, 1, in) == 1) {
    memcpy(nav.position_ned_m, r, sizeof nav.position_ned_m);
    auvrl_policy_integrate_goal(offset_ned_m, &nav, r + 3, moved_goal_ned_m);
    if (fwrite(moved_goal_ned_m, sizeof moved_goal_ned_m, 1, out) != 1) return 1;
  }
  return 0;
}

static int filter_position(FILE *in, FILE *out) {
  double r[9];
  auvrl_position_filter filter;
  auvrl_nav nav;
  memset(&filter, 0, sizeof filter);
  memset(&nav, 0, sizeof nav);
  while (fread(r, sizeof r, 1, in) == 1) {
    memcpy(nav.position_ned_m, r, sizeof nav.position_ned_m);
    memcpy(nav.euler_rpy_rad, r + 3, sizeof nav.euler_rpy_rad);
    memcpy(nav.velocity_body_mps, r + 6, sizeof nav.velocity_body_mps);
    auvrl_policy_filter_position(&filter, &nav);
    if (fwrite(nav.position_ned_m, sizeof nav.position_ned_m, 1, out) != 1) return 1;
  }
  return 0;
}

static int accommodate_faults(FILE *in, FILE *out) {
  float r[AUVRL_POLICY_STATE_DIM + AUVRL_POLICY_NUM_ACTIONS];
  auvrl_fault_accommodation faults;
  memset(&faults, 0, sizeof faults);
  while (fread(r, sizeof r, 1, in) == 1) {
    float *action = r + AUVRL_POLICY_STATE_DIM;
    auvrl_policy_accommodate_faults(&faults, r, action);
    if (fwrite(action, sizeof(float) * AUVRL_POLICY_NUM_ACTIONS, 1, out) != 1) return 1;
  }
  return 0;
}

int main(int argc, char **argv) {
  FILE *in = NULL, *out = NULL;
  int status = 2;
  if (argc == 3 && strcmp(argv[1], "params") == 0) {
    out = fopen(argv[2], "wb");
    if (out == NULL) return 1;
    status = fwrite(auvrl_policy_params, sizeof auvrl_policy_params, 1, out) == 1 ? 0 : 1;
    return fclose(out) == 0 ? status : 1;
  }
  if (argc != 4) {
    fprintf(stderr,
            "usage: policy_driver act|state|integrate|filter|faults IN OUT, or policy_driver "
            "params OUT\n");
    return 2;
  }
  in = fopen(argv[2], "rb");
  out = fopen(argv[3], "wb");
  if (in != NULL && out != NULL) {
    if (strcmp(argv[1], "act") == 0) status = act(in, out);
    if (strcmp(argv[1], "state") == 0) status = build_state(in, out);
    if (strcmp(argv[1], "integrate") == 0) status = integrate(in, out);
    if (strcmp(argv[1], "filter") == 0) status = filter_position(in, out);
    if (strcmp(argv[1], "faults") == 0) status = accommodate_faults(in, out);
  } else {
    status = 1;
  }
  if (in != NULL) fclose(in);
  if (out != NULL && fclose(out) != 0) status = 1;
  return status;
}
