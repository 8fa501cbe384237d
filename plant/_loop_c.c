/* The harness's closed loop around the plant, in C: a whole log in one call.
 *
 * Per sample k, in the order of validation/harness/loop.py's Python loop (the
 * reference this is tested against, within 1e-9):
 *
 *   1. the reversing feedback law: delta = delta_c + w K wrap(gamma - gamma_meas),
 *      w the feedback's weight in [0, 1] (1 while the log reverses, 0 otherwise,
 *      ramping between: validation/harness/reversing.py), limited to +-delta_max;
 *   2. the signals at the two sensor points (Plant.observe), and a gathered
 *      row of raw outputs for Plant.extras;
 *   3. a stop when the articulation passes gamma_max or a signal is not finite;
 *   4. otherwise Plant.step: the steering servos, the speed follower sampled
 *      at the middle of the interval (the commanded ramp's mean, at dt / 2,
 *      whatever the step), n = round(dt / h) MuJoCo steps, and the divergence
 *      check.
 *
 * The tyre forces come from MuJoCo's passive callback as always (the compiled
 * one, plant/_tyre_c.c). Nothing here is global: the loop's state lives in
 * the artic_loop struct the caller owns, so any number of plants can run on
 * threads. Python calls this through ctypes, which releases the GIL.
 *
 * artic_step and artic_observe are Plant.step (after Python has set the
 * speed controls) and Plant.observe on their own, for plants that Python
 * drives one step at a time: the synthetic truth's drivers, whose decisions
 * stay in Python. They share this file's code with the whole-log loop.
 *
 * artic_ramp_steps is a docking run's ten plant steps between two controller
 * samples (validation/docking/run.py): the actuators ramping towards their
 * targets at their rate limits, the steering map, Plant.step and Plant.observe
 * and the jackknife check, per plant step, in that loop's order and arithmetic,
 * so that its traces are the Python loop's to the bit.
 *
 * The call returns early, with the struct ready to resume at sample k + 1,
 * when Python has something to do that needs the state of that moment: a
 * loaded wheel went outside the tyre file's ranges (Python names it), or the
 * simulation diverged (Python raises, naming the wheel).
 */
#include <math.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "extensions.h" /* mjcf/: what artic's extensions export to their loader */

#define ARTIC_LOOP_ABI 4
#define N_OBS 13
#define MAX_SERVOS 4
#define MAX_WHEELS 64

enum { LOOP_DONE = 0, LOOP_STOPPED = 1, LOOP_TYRE_RANGE = 3, LOOP_DIVERGED = 4, LOOP_BAD = 5 };

/* Sources of the gathered raw outputs (plant/closedloop.py SOURCES). */
enum { SRC_QPOS, SRC_XPOS, SRC_XQUAT, SRC_SITE_XPOS, SRC_USERDATA, SRC_ACT, SRC_ACTUATOR_FORCE,
       SRC_ZERO, N_SRC };

static const double PI = 3.14159265358979323846;

typedef struct {
  /* the model */
  int tractor_body, trailer_body, sensor_site[2], hitch_qpos;
  int n_servo, servo[MAX_SERVOS];
  double servo_lo, servo_hi;
  int follower;
  double follower_kv, mass_eff, rr_coef, follow_ki;
  double sensor_yaw[2];
  int n_wheels;
  /* the harness */
  double gain, delta_max, gamma_max;
  int n_gather;
  const int* gather; /* n_gather (source, index) pairs */
  /* state, carried across calls */
  int k;
  double psi[2], integral;
  int steer_limited;
  double first_limit_time, first_limit_delta;
  /* the last step's report */
  double good_time, span;
  double good_forces[3 * MAX_WHEELS];
} artic_loop;

/* artic.mjcf.interface.wrap_angle: pi - numpy.mod(pi - a, 2 pi), numpy's remainder exactly. */
static double wrap_angle(double a) {
  double x = PI - a, b = 2.0 * PI;
  double mod = fmod(x, b);
  if (mod != 0.0) {
    if ((b < 0.0) != (mod < 0.0)) mod += b;
  } else {
    mod = copysign(0.0, b);
  }
  return PI - mod;
}

/* artic.validation.harness.loop.wrap: a - 2 pi floor((a + pi) / (2 pi)). */
static double wrap(double a) { return a - 2.0 * PI * floor((a + PI) / (2.0 * PI)); }

/* Plant.observe */
static void observe(const mjModel* m, mjData* d, artic_loop* s, double* out) {
  double res[6];
  for (int i = 0; i < 2; i++) {
    int body = i == 0 ? s->tractor_body : s->trailer_body, site = s->sensor_site[i];
    const mjtNum* R = d->xmat + 9 * body;
    double psi = atan2(R[3], R[0]);
    psi = s->psi[i] + wrap_angle(psi - s->psi[i]);
    s->psi[i] = psi;
    mj_objectVelocity(m, d, mjOBJ_SITE, site, res, 1);
    double vx = res[3], vy = res[4], eps = s->sensor_yaw[i];
    if (eps != 0.0) {
      double c = cos(eps), sn = sin(eps);
      double vx2 = c * vx + sn * vy, vy2 = -sn * vx + c * vy;
      vx = vx2;
      vy = vy2;
    }
    double* o = out + 6 * i;
    o[0] = d->site_xpos[3 * site];
    o[1] = d->site_xpos[3 * site + 1];
    o[2] = psi + eps;
    o[3] = vx;
    o[4] = vy;
    o[5] = res[2];
  }
  out[12] = wrap_angle(out[2] - out[8]);
}

static void gather(const mjModel* m, const mjData* d, const artic_loop* s, double* row) {
  const mjtNum* src[N_SRC] = {d->qpos, d->xpos, d->xquat, d->site_xpos, d->userdata, d->act,
                              d->actuator_force, NULL};
  for (int j = 0; j < s->n_gather; j++) {
    int what = s->gather[2 * j], idx = s->gather[2 * j + 1];
    row[j] = what == SRC_ZERO ? 0.0 : src[what][idx];
  }
}

/* Plant._speed: the tractor's speed along its x-axis [m/s]. */
static double speed(const mjData* d, const artic_loop* s) {
  const mjtNum* R = d->xmat + 9 * s->tractor_body;
  return R[0] * d->qvel[0] + R[3] * d->qvel[1] + R[6] * d->qvel[2];
}

/* Indices the loop follows, checked once against the model and the struct's bounds. */
static int sound(const mjModel* m, const artic_loop* s) {
  if (s->tractor_body < 0 || s->tractor_body >= m->nbody || s->trailer_body < 0
      || s->trailer_body >= m->nbody || s->hitch_qpos < 0 || s->hitch_qpos >= m->nq
      || s->follower < 0 || s->follower >= m->nu || s->n_servo < 0 || s->n_servo > MAX_SERVOS
      || s->n_wheels < 0 || s->n_wheels > MAX_WHEELS || m->nuserdata < 3 * s->n_wheels + 1
      || s->n_gather < 0 || (s->n_gather > 0 && s->gather == NULL)) {
    return 0;
  }
  for (int i = 0; i < 2; i++)
    if (s->sensor_site[i] < 0 || s->sensor_site[i] >= m->nsite) return 0;
  for (int i = 0; i < s->n_servo; i++)
    if (s->servo[i] < 0 || s->servo[i] >= m->nu) return 0;
  int size[N_SRC] = {m->nq, 3 * m->nbody, 4 * m->nbody, 3 * m->nsite, m->nuserdata, m->na,
                     m->nu, 1};
  for (int j = 0; j < s->n_gather; j++) {
    int what = s->gather[2 * j], idx = s->gather[2 * j + 1];
    if (what < 0 || what >= N_SRC || idx < 0 || idx >= size[what]) return 0;
  }
  return 1;
}

/* Plant.step after the speed controls: the steering servos (a demand beyond
 * the linkage is counted, the first one's time and angle kept), nsub MuJoCo
 * steps, the divergence check and the tyre files' range flag. */
static int servo_and_steps(const mjModel* m, mjData* d, artic_loop* s, double dl, int nsub) {
  double lo = s->servo_lo, hi = s->servo_hi;
  if (!(lo <= dl && dl <= hi)) {
    if (++s->steer_limited == 1) {
      s->first_limit_time = d->time;
      s->first_limit_delta = dl;
    }
  }
  double applied = lo > dl ? lo : dl; /* Python's min(max(dl, lo), hi): NaN passes */
  applied = hi < applied ? hi : applied;
  for (int i = 0; i < s->n_servo; i++) d->ctrl[s->servo[i]] = applied;
  s->good_time = d->time;
  s->span = nsub * m->opt.timestep;
  memcpy(s->good_forces, d->userdata, sizeof(double) * 3 * s->n_wheels);
  for (int i = 0; i < nsub; i++) mj_step(m, d);
  int bad = 0;
  for (int i = 0; i < mjNWARNING; i++) bad = bad || d->warning[i].number;
  for (int i = 0; i < m->nv; i++) bad = bad || !isfinite(d->qvel[i]);
  if (bad) return LOOP_DIVERGED;
  if (d->userdata[3 * s->n_wheels] != 0.0) return LOOP_TYRE_RANGE;
  return LOOP_DONE;
}

/* artic_loop_abi, artic_loop_mj_version, ... (extensions.h); the loop has no block */
ARTIC_EXPORTS(artic_loop, ARTIC_LOOP_ABI)

int artic_loop_size(void) { return (int)sizeof(artic_loop); }

/* Run samples s->k .. n - 1 of a log. Returns a LOOP_* code; *n_done is the
 * number of rows filled so far (all of them on LOOP_DONE). */
int artic_run_loop(const mjModel* m, mjData* d, artic_loop* s, int n, const double* dt,
                   const double* delta_c, const double* u1, const double* u1_dot,
                   const double* gamma_meas, const double* weight, double* obs,
                   double* delta, double* delta_fb, unsigned char* sat, double* raw,
                   int* n_done) {
  if (!sound(m, s)) return LOOP_BAD;
  double h = m->opt.timestep;
  for (int k = s->k; k < n; k++) {
    /* 1. the feedback law (artic.validation.harness.feedback.feedback_law) */
    /* as the inertial units report it: the hitch angle and their mounting yaws (Plant.gamma) */
    double gamma = wrap_angle(-d->qpos[s->hitch_qpos] + s->sensor_yaw[0] - s->sensor_yaw[1]);
    /* w K wrap(e) in feedback_law's order, (w K) wrap(e); none at all where w = 0 */
    double fb = weight[k] != 0.0 ? weight[k] * s->gain * wrap(gamma - gamma_meas[k]) : 0.0;
    double dl = delta_c[k] + fb;
    unsigned char limited = 0;
    if (dl > s->delta_max) {
      dl = s->delta_max;
      limited = 1;
    } else if (dl < -s->delta_max) {
      dl = -s->delta_max;
      limited = 1;
    }
    /* 2. the signals and the raw outputs */
    double* o = obs + N_OBS * k;
    observe(m, d, s, o);
    delta[k] = dl;
    delta_fb[k] = dl - delta_c[k];
    sat[k] = limited;
    if (s->n_gather) gather(m, d, s, raw + (size_t)s->n_gather * k);
    /* 3. the stop */
    int finite = 1;
    for (int j = 0; j < N_OBS; j++) finite = finite && isfinite(o[j]);
    if (fabs(o[12]) > s->gamma_max || !finite) {
      *n_done = k + 1;
      s->k = n;
      return LOOP_STOPPED;
    }
    *n_done = k + 1;
    if (k + 1 >= n) break;
    /* 4. Plant.step: the servos, the speed follower, the steps, the check */
    int nsub = (int)nearbyint(dt[k] / h);
    if (nsub < 1) nsub = 1;
    double u_cmd = u1[k] + u1_dot[k] * 0.5 * (nsub * h);
    double e = u_cmd - speed(d, s);
    s->integral += e * (nsub * h);
    double rr = s->rr_coef * tanh(u_cmd / 0.1);
    double ff = s->mass_eff * u1_dot[k] + rr;
    d->ctrl[s->follower] = u_cmd + ff / s->follower_kv + s->follow_ki * s->integral;
    s->k = k + 1;
    int code = servo_and_steps(m, d, s, dl, nsub);
    if (code != LOOP_DONE) return code;
  }
  s->k = n;
  return LOOP_DONE;
}

/* Plant.step once Python has set the speed controls: nsub steps at road-wheel
 * angle delta [rad]. Returns LOOP_DONE, LOOP_DIVERGED, LOOP_TYRE_RANGE or LOOP_BAD. */
int artic_step(const mjModel* m, mjData* d, artic_loop* s, double delta, int nsub) {
  if (!sound(m, s)) return LOOP_BAD;
  return servo_and_steps(m, d, s, delta, nsub < 1 ? 1 : nsub);
}

/* Plant.observe into out[13]. Returns LOOP_DONE or LOOP_BAD. */
int artic_observe(const mjModel* m, mjData* d, artic_loop* s, double* out) {
  if (!sound(m, s)) return LOOP_BAD;
  observe(m, d, s, out);
  return LOOP_DONE;
}

/* A docking run's actuators between two controller samples (plant/closedloop.py Ramp). */
typedef struct {
  /* state, carried across calls */
  double wheel, u, t;
  /* per plant step: the largest change of the steering wheel [rad] and of the speed [m/s] */
  double wheel_step, u_step;
  /* the steering map of eq. (3): delta = (d - q d^2) / i_s, d = wheel - offset */
  double offset, q, i_s;
  double dt, gamma_max;
  /* plant steps per call, the next one (a call resumes there), and the tyre files'
   * range flag of the last step taken */
  int n, j, tyre_range;
} artic_ramp;

int artic_ramp_size(void) { return (int)sizeof(artic_ramp); }

/* Python's min(max(x, -lim), lim), signed zeros included. */
static double limited(double x, double lim) {
  double y = -lim > x ? -lim : x;
  return lim < y ? lim : y;
}

/* Plant steps r->j .. r->n - 1, each: the steering wheel and the speed one rate-limited
 * step towards target[2 j], target[2 j + 1]; the road-wheel angle of the steering map;
 * Plant.step (the speed follower at the ramp's middle, the servos, the steps, the check);
 * the signals into obs[13 j ...] and (wheel, speed, time) into log[3 j ...]; the
 * articulation against gamma_max. Returns LOOP_DONE; LOOP_STOPPED past gamma_max (its
 * step filled); LOOP_TYRE_RANGE after a step that flagged a wheel (filled; Python names
 * it, resets the flag and calls again); LOOP_DIVERGED (that step not filled); LOOP_BAD. */
int artic_ramp_steps(const mjModel* m, mjData* d, artic_loop* s, artic_ramp* r,
                     const double* target, double* obs, double* log) {
  if (!sound(m, s)) return LOOP_BAD;
  double h = m->opt.timestep;
  int nsub = (int)nearbyint(r->dt / h);
  if (nsub < 1) nsub = 1;
  r->tyre_range = 0;
  for (int j = r->j; j < r->n; j++) {
    double u = r->u;
    double wheel = r->wheel + limited(target[2 * j] - r->wheel, r->wheel_step);
    double u_next = u + limited(target[2 * j + 1] - u, r->u_step);
    double dw = wheel - r->offset; /* Steering.road_wheel */
    double delta = (dw - r->q * dw * dw) / r->i_s;
    double u1_dot = (u_next - u) / r->dt;
    /* Plant._control, the speed followed, sampled at the middle of the interval */
    double u_cmd = u + u1_dot * 0.5 * (nsub * h);
    double e = u_cmd - speed(d, s);
    s->integral += e * (nsub * h);
    double rr = s->rr_coef * tanh(u_cmd / 0.1);
    double ff = s->mass_eff * u1_dot + rr;
    d->ctrl[s->follower] = u_cmd + ff / s->follower_kv + s->follow_ki * s->integral;
    int code = servo_and_steps(m, d, s, delta, nsub);
    if (code == LOOP_DIVERGED) {
      r->j = j;
      return code;
    }
    r->wheel = wheel;
    r->u = u_next;
    r->t = r->t + r->dt;
    observe(m, d, s, obs + N_OBS * j);
    log[3 * j] = wheel;
    log[3 * j + 1] = u_next;
    log[3 * j + 2] = r->t;
    r->j = j + 1;
    r->tyre_range = code == LOOP_TYRE_RANGE;
    double gamma = wrap_angle(-d->qpos[s->hitch_qpos] + s->sensor_yaw[0] - s->sensor_yaw[1]);
    if (fabs(gamma) > r->gamma_max) return LOOP_STOPPED;
    if (r->tyre_range) return LOOP_TYRE_RANGE;
  }
  return LOOP_DONE;
}
