/* The synthetic truth's own tyres and steering, as a MuJoCo passive callback.
 *
 * This is the measured vehicle of artic's synthetic campaign, not the plant
 * under validation: it shares neither the plant's tyre formula (PAC2002,
 * plant/_tyre_c.c) nor its steering (a stiff position servo and a fitted
 * tie-rod polynomial). What it computes, per integrator stage:
 *
 * Tyres: TMeasy, "Tire Model Made Easy", from G. Rill, "Road Vehicle
 * Dynamics: Fundamentals and Modeling", CRC Press 2011, chapter 3:
 *   - the generalised slip of combined longitudinal, lateral and bore slip
 *     (3.3.8), each normalised by the characteristic's own scale, and one
 *     generalised characteristic F(s): a rational function up to the peak
 *     (dF0, sM, FM), a cubic to the sliding point (sS, FS), constant after;
 *   - load dependence: forces and slopes quadratic through 0, Fz_N and 2 Fz_N,
 *     slips linear (3.3.7);
 *   - aligning torque from the pneumatic trail n(s_y) = L (n/L)(s_y), a
 *     linear and a cubic law weighted, negative before it vanishes (3.3.5);
 *   - bore torque M_B = R_B F(s_G) s_B / s_G with R_B = (L / 2 + B / 2) / 3
 *     (3.3.6), the contact patch L long and B wide;
 *   - first-order dynamics of the tyre's deflections x_e, y_e and twist
 *     phi_e (3.4): each force is its spring and damper, c x_e + d dx_e/dt,
 *     equal to the steady force at the slip that includes the deflection rate,
 *     linearised by the global derivative f / s, which gives
 *       dx_e/dt = -(v* s*_x c_x x_e + (f/s) v_sx) / (v* s*_x d_x + f/s)
 *     with v* = r_D |Omega| + v_N. v_N > 0 keeps it sound through standstill
 *     and reverse: no division by the speed anywhere.
 *   Twin tyres are two tyres, each at its own contact point, load and slip.
 *   The steered wheels' kingpins lead their contact points by the caster
 *   trail: the hinge of the model stands at the wheel centre, so the trail
 *   enters as what it does, a lateral velocity -trail * (steering rate) at
 *   the contact and the torque -trail * Fy on the steering hinge alone (an
 *   internal torque, knuckle against axle: the same power, no net moment).
 *
 * Steering: a compliant column. The steering-wheel angle reaches the box
 * through a torsion bar with free play; a hydraulic assist adds a lagged,
 * saturating multiple of the torsion-bar torque; the left knuckle takes the
 * sum, the right one follows through a tie rod of finite stiffness joining
 * the two steering arms (the trapezoid's exact geometry, not a fit). The
 * steering-wheel angle, as a left-wheel angle, is the ctrl of a zero-gain
 * actuator the caller sets (the plant's servo slot); the assist torque is the
 * activation of an integrator actuator whose rate this writes.
 *
 * Speed following (the floor's, under the harness): the plant's speed follower
 * is a velocity servo pushing the drive axle at the ground. The truth's own
 * driver pushes through its driven wheels and brakes all of them, which the
 * tyres feel (traction slip, and the braked semitrailer's pull when it stops),
 * so here the follower's force, kv (ctrl - v) along the drive axle as the
 * servo's, is applied as the truth's drive and brakes apply theirs: drive
 * torque shared by the driven wheels while it pushes the way of travel,
 * brake torque shared by all wheels in proportion to their static loads
 * while it holds back. The model's follower actuator keeps its gain (the
 * plant's controller reads it) and has no transmission of its own.
 *
 * The block: numeric 0 "artic.truth", sealed with the process's key and a
 * checksum, checked against the model before it is followed (as the plant's
 * own, plant/_tyre_c.c); a foreign or damaged block gets no force. Per wheel
 * end the sum of its tyres' forces goes to d->userdata[3 i .. 3 i + 2];
 * d->userdata[3 n] stays 0 (the plant's out-of-range count); then the knuckle
 * torque of the column, the torsion-bar torque at the steering wheel and the
 * tie rod's torque on the right knuckle [N m].
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "extensions.h" /* mjcf/: the sealed block's key, checksum and memory, as the plant's */

#define TRUTH_ABI 1
#define BLOCK_NAME "artic.truth"
/* abi, key_hi, key_lo, n_ends, n_sets, n_tyre_params, n_columns, checksum, then the
 * speed follower: follow (0 or 1), kv [N s/m], its actuator (ctrl), its site */
#define HEADER 12
enum { H_FOLLOW = 8, H_KV, H_FOLLOWER, H_SITE };
#define MAX_TYRES 2
#define N_DIAG 3

/* One tyre's coefficients, in block order (validation/synthetic/tmeasy.py). */
#define TYRE_PARAMS(X) \
  X(r0) X(cz) X(dz) X(fzn) X(width) X(fzmax) \
  X(dfx0_1) X(dfx0_2) X(fxm_1) X(fxm_2) X(sxm_1) X(sxm_2) X(fxs_1) X(fxs_2) X(sxs_1) X(sxs_2) \
  X(dfy0_1) X(dfy0_2) X(fym_1) X(fym_2) X(sym_1) X(sym_2) X(fys_1) X(fys_2) X(sys_1) X(sys_2) \
  X(nto0_1) X(nto0_2) X(synto0_1) X(synto0_2) X(syntoe_1) X(syntoe_2) \
  X(cx) X(dx) X(cy) X(dy) X(cpsi) X(dpsi) X(fr) X(vn)

/* The steering column, in block order (validation/synthetic/column.py); the
 * model ids last. */
#define COLUMN_PARAMS(X) \
  X(i_s) X(k_tb) X(play) X(play_smooth) X(boost) X(assist_max) X(assist_tau) X(c_kingpin) \
  X(track) X(arm) X(beta) X(rod) X(k_rod) X(c_rod) \
  X(slot) X(steer_l_qpos) X(steer_l_dof) X(steer_r_qpos) X(steer_r_dof) X(assist_act) \
  X(assist_ctrl)

/* Per wheel end: ids, its tyres' set, twin spacing and trail, then per tyre
 * its deflection states' activations and controls. */
#define END_FIELDS(X) \
  X(hub_site) X(hub_body) X(root_body) X(wheel_body) X(spin_dof) X(n_tyres) X(tyre_set) \
  X(half_spacing) X(trail) X(steer_dof) X(drive_share) X(brake_share) \
  X(act_x1) X(act_y1) X(act_p1) X(ctrl_x1) X(ctrl_y1) X(ctrl_p1) \
  X(act_x2) X(act_y2) X(act_p2) X(ctrl_x2) X(ctrl_y2) X(ctrl_p2)

#define ENUM_T(name) T_##name,
#define ENUM_C(name) C_##name,
#define ENUM_E(name) E_##name,
enum { TYRE_PARAMS(ENUM_T) N_TYRE };
enum { COLUMN_PARAMS(ENUM_C) N_COLUMN };
enum { END_FIELDS(ENUM_E) N_END };
#define STR(name) #name ","
static const char tyre_names[] = TYRE_PARAMS(STR);
static const char column_names[] = COLUMN_PARAMS(STR);
static const char end_names[] = END_FIELDS(STR);

static const double TINY = 1e-12;
static const double SQRT1_2 = 0.70710678118654752440;
static const double V_SMOOTH = 0.05; /* [m/s] width of the smoothed sign of travel and rolling */

static double pos_(double x) { return x > TINY ? x : TINY; }

/* ------------------------------------------------------------------ TMeasy */

/* Load dependence (Rill 3.3.7): through 0, X1 at Fz_N and X2 at 2 Fz_N. */
static double interp_q(double r, double x1, double x2) {
  return r * (x1 * (2.0 - r) + x2 * 0.5 * (r - 1.0));
}

static double interp_l(double r, double x1, double x2) { return x1 + (x2 - x1) * (r - 1.0); }

/* The generalised characteristic F(s), s >= 0, and the global derivative F / s. */
static void characteristic(double s, double dF0, double sM, double FM, double sS, double FS,
                           double* F, double* fos) {
  /* the rational part has no inflection before the peak while dF0 >= 2 FM / sM */
  dF0 = fmax(dF0, 2.0 * FM / sM);
  if (s <= sM) {
    double sig = s / sM;
    double den = 1.0 + sig * (sig + dF0 * sM / FM - 2.0);
    *F = dF0 * s / den;
    *fos = dF0 / den;
  } else if (s < sS) {
    double sig = (s - sM) / (sS - sM);
    *F = FM - (FM - FS) * sig * sig * (3.0 - 2.0 * sig);
    *fos = *F / s;
  } else {
    *F = FS;
    *fos = FS / s;
  }
}

/* Tyre offset over patch length, n / L, at |s_y| (Rill 3.3.5). */
static double trail_ratio(double sy, double n0, double s0, double sE) {
  sy = fabs(sy);
  sE = fmax(sE, s0 * (1.0 + 1e-9));
  if (sy >= sE) return 0.0;
  double w = s0 / sE;
  if (sy <= s0) {
    double x = sy / s0;
    return n0 * ((1.0 - w) * (1.0 - x) + w * (1.0 - (3.0 - 2.0 * x) * x * x));
  }
  double z = (sE - sy) / (sE - s0);
  return -n0 * (1.0 - w) * (sy - s0) / s0 * z * z;
}

/* Everything of one tyre at one load that the slips do not change, and the
 * generalised characteristic at the slips. */
typedef struct {
  double hsx, hsy;    /* slip normalisation s*_x, s*_y */
  double L, RB;       /* patch length, bore radius [m] */
  double nto0, synto0, syntoe;
  double F, fos;      /* generalised force [N] and global derivative F / s */
} slip_state;

static int loaded(const double* p, double Fz) { return Fz > 1e-3 * p[T_fzn]; }

/* Contact patch length L = 2 sqrt(r0 dz) at the load's deflection, and the bore
 * radius R_B = (2/3) (L/2 + B/2) / 2 (Rill 3.3.6) [m]. */
static double patch_length(const double* p, double Fz) {
  return 2.0 * sqrt(p[T_r0] * fmax(Fz, 0.0) / p[T_cz]);
}

static double bore_radius(const double* p, double Fz) {
  return (0.5 * patch_length(p, Fz) + 0.5 * p[T_width]) / 3.0;
}

static void evaluate(const double* p, double Fz, double sx, double sy, double sB,
                     slip_state* o) {
  double r = fmin(Fz, p[T_fzmax]) / p[T_fzn];
  double dfx0 = pos_(interp_q(r, p[T_dfx0_1], p[T_dfx0_2]));
  double dfy0 = pos_(interp_q(r, p[T_dfy0_1], p[T_dfy0_2]));
  double fxm = pos_(interp_q(r, p[T_fxm_1], p[T_fxm_2]));
  double fym = pos_(interp_q(r, p[T_fym_1], p[T_fym_2]));
  double fxs = fmin(pos_(interp_q(r, p[T_fxs_1], p[T_fxs_2])), fxm);
  double fys = fmin(pos_(interp_q(r, p[T_fys_1], p[T_fys_2])), fym);
  /* slips: linear in the load, kept positive and ordered at small loads */
  double sxm = fmax(interp_l(r, p[T_sxm_1], p[T_sxm_2]), 0.1 * p[T_sxm_1]);
  double sym = fmax(interp_l(r, p[T_sym_1], p[T_sym_2]), 0.1 * p[T_sym_1]);
  double sxs = fmax(interp_l(r, p[T_sxs_1], p[T_sxs_2]), 1.01 * sxm);
  double sys = fmax(interp_l(r, p[T_sys_1], p[T_sys_2]), 1.01 * sym);
  double ax = fxm / dfx0, ay = fym / dfy0;
  o->hsx = sxm / (sxm + sym) + ax / (ax + ay);
  o->hsy = sym / (sxm + sym) + ay / (ax + ay);
  o->L = patch_length(p, Fz);
  o->RB = bore_radius(p, Fz);
  o->nto0 = interp_l(r, p[T_nto0_1], p[T_nto0_2]);
  o->synto0 = fmax(interp_l(r, p[T_synto0_1], p[T_synto0_2]), 1e-3);
  o->syntoe = fmax(interp_l(r, p[T_syntoe_1], p[T_syntoe_2]), o->synto0 * 1.01);
  double xn = sx / o->hsx, yn = sy / o->hsy;
  double sc = hypot(xn, yn), sg = hypot(sc, sB);
  double c = SQRT1_2, s = SQRT1_2; /* no direction without slip: both alike */
  if (sc > 0.0) {
    c = fabs(xn) / sc;
    s = fabs(yn) / sc;
  }
  double dF0 = hypot(dfx0 * o->hsx * c, dfy0 * o->hsy * s);
  double sM = hypot(sxm / o->hsx * c, sym / o->hsy * s);
  double FM = hypot(fxm * c, fym * s);
  double sS = hypot(sxs / o->hsx * c, sys / o->hsy * s);
  double FS = hypot(fxs * c, fys * s);
  characteristic(sg, dF0, sM, FM, sS, FS, &o->F, &o->fos);
}

/* The smoothed sign of a speed [m/s]. */
static double travel_sign(double v) { return v / sqrt(v * v + V_SMOOTH * V_SMOOTH); }

/* One tyre: steady slips from the contact's velocities, deflection rates,
 * the dynamic forces and moments. v_roll = r_D Omega, omega_n the yaw rate
 * about the ground normal. */
static void tyre(const double* p, double Fz, double vx, double vy, double v_roll, double omega_n,
                 double xe, double ye, double pe, double* Fx, double* Fy, double* Mz, double* My,
                 double* dxe, double* dye, double* dpe) {
  if (!loaded(p, Fz)) { /* in the air: no force; the deflections relax on their dampers */
    *Fx = *Fy = *Mz = *My = 0.0;
    *dxe = -p[T_cx] / p[T_dx] * xe;
    *dye = -p[T_cy] / p[T_dy] * ye;
    *dpe = -p[T_cpsi] / p[T_dpsi] * pe;
    return;
  }
  double vstar = fabs(v_roll) + p[T_vn];
  double vsx = vx - v_roll;
  slip_state o;
  double sB = -bore_radius(p, Fz) * omega_n / vstar;
  evaluate(p, Fz, -vsx / vstar, -vy / vstar, sB, &o);
  double f = o.fos, ax = vstar * o.hsx, ay = vstar * o.hsy, rb2 = o.RB * o.RB;
  *dxe = -(ax * p[T_cx] * xe + f * vsx) / (ax * p[T_dx] + f);
  *dye = -(ay * p[T_cy] * ye + f * vy) / (ay * p[T_dy] + f);
  *dpe = -(vstar * p[T_cpsi] * pe + rb2 * f * omega_n) / (vstar * p[T_dpsi] + rb2 * f);
  *Fx = p[T_cx] * xe + p[T_dx] * *dxe;
  *Fy = p[T_cy] * ye + p[T_dy] * *dye;
  double bore = p[T_cpsi] * pe + p[T_dpsi] * *dpe;
  /* the lateral slip the dynamic force stands for, for the trail */
  double sy_dyn = *Fy * o.hsy / f;
  double n = o.L * trail_ratio(sy_dyn, o.nto0, o.synto0, o.syntoe);
  *Mz = -n * *Fy * travel_sign(vx) + bore;
  *My = -p[T_fr] * Fz * p[T_r0] * travel_sign(v_roll);
}

/* ------------------------------------------------------------------ steering */

/* A dead zone of half-width h, smoothed over w: 0 inside, x -+ h outside. */
static double dead_zone(double x, double h, double w) {
  double a = x - h, b = x + h;
  return 0.5 * (a + sqrt(a * a + w * w)) + 0.5 * (b - sqrt(b * b + w * w));
}

/* Column torques on the knuckles at steering demand ref (a left-wheel angle),
 * the knuckles at dl, dr turning at wl, wr, the assist at Ta. Writes the
 * knuckle torques, the assist's rate and the diagnostics. */
static void column_law(const double* c, double ref, double dl, double dr, double wl, double wr,
                       double Ta, double* TL, double* TR, double* dTa, double* diag) {
  double tb = c[C_k_tb] * dead_zone(c[C_i_s] * (ref - dl), 0.5 * c[C_play], c[C_play_smooth]);
  double target = c[C_assist_max] * tanh(c[C_boost] * c[C_i_s] * tb / c[C_assist_max]);
  *dTa = (target - Ta) / c[C_assist_tau];
  double box = c[C_i_s] * tb + Ta;
  /* the tie rod: arm tips of length arm at beta inward-back, kingpins track apart */
  double lx = -c[C_arm] * cos(c[C_beta]), ly = c[C_arm] * sin(c[C_beta]);
  double cl = cos(dl), sl = sin(dl), cr = cos(dr), sr = sin(dr);
  double px = (cl * lx + sl * ly) - (cr * lx - sr * ly);
  double py = (0.5 * c[C_track] + sl * lx - cl * ly) - (-0.5 * c[C_track] + sr * lx + cr * ly);
  double len = hypot(px, py);
  double gl = (px * (-sl * lx + cl * ly) + py * (cl * lx + sl * ly)) / len;  /* dlen / d dl */
  double gr = -(px * (-sr * lx - cr * ly) + py * (cr * lx - sr * ly)) / len; /* dlen / d dr */
  double force = c[C_k_rod] * (len - c[C_rod]) + c[C_c_rod] * (gl * wl + gr * wr);
  *TL = box - force * gl - c[C_c_kingpin] * wl;
  *TR = -force * gr - c[C_c_kingpin] * wr;
  diag[0] = box;
  diag[1] = tb;
  diag[2] = -force * gr;
}

/* ------------------------------------------------------------------ forces */

/* qfrc += J' [F; T] of `point` on `body` (mj_applyFT's sum along the chain). The
 * plant's callback has the same sum; the truth keeps its own copy on purpose, as a
 * reference shares no code with the plant it validates. */
static void apply_ft(const mjModel* m, const mjData* d, const double F[3], const double T[3],
                     const double point[3], int body, mjtNum* qfrc) {
  while (body > 0 && m->body_dofnum[body] == 0) body = m->body_parentid[body];
  if (body <= 0) return;
  const mjtNum* c = d->subtree_com + 3 * m->body_rootid[body];
  double o[3] = {point[0] - c[0], point[1] - c[1], point[2] - c[2]};
  double tc[3] = {T[0] + o[1] * F[2] - o[2] * F[1], T[1] + o[2] * F[0] - o[0] * F[2],
                  T[2] + o[0] * F[1] - o[1] * F[0]};
  for (int j = m->body_dofadr[body] + m->body_dofnum[body] - 1; j >= 0; j = m->dof_parentid[j]) {
    const mjtNum* s = d->cdof + 6 * j;
    qfrc[j] += s[0] * tc[0] + s[1] * tc[1] + s[2] * tc[2] + s[3] * F[0] + s[4] * F[1]
               + s[5] * F[2];
  }
}

/* Velocity of a point fixed to a body: its cvel about the root's subtree centre. */
static void point_velocity(const mjData* d, int body, int root, const double p[3],
                           double v[3]) {
  const mjtNum* cv = d->cvel + 6 * body;
  const mjtNum* com = d->subtree_com + 3 * root;
  double r[3] = {p[0] - com[0], p[1] - com[1], p[2] - com[2]};
  v[0] = cv[3] + cv[1] * r[2] - cv[2] * r[1];
  v[1] = cv[4] + cv[2] * r[0] - cv[0] * r[2];
  v[2] = cv[5] + cv[0] * r[1] - cv[1] * r[0];
}

/* The follower's force [N] along the drive axle: the velocity servo's law. */
static double follower_force(const mjModel* m, const mjData* d, const double* blk) {
  int site = (int)blk[H_SITE], body = m->site_bodyid[site];
  const mjtNum* R = d->site_xmat + 9 * site;
  double v[3];
  point_velocity(d, body, m->body_rootid[body], d->site_xpos + 3 * site, v);
  double along = v[0] * R[0] + v[1] * R[3] + v[2] * R[6];
  return blk[H_KV] * (d->ctrl[(int)blk[H_FOLLOWER]] - along);
}

static void wheel_end(const mjModel* m, mjData* d, const double* p, const double* e,
                      double* sum) {
  int hub = (int)e[E_hub_site], hub_body = (int)e[E_hub_body], root = (int)e[E_root_body];
  int wheel_body = (int)e[E_wheel_body], spin = (int)e[E_spin_dof], n = (int)e[E_n_tyres];
  double trail = e[E_trail];
  const mjtNum* R = d->site_xmat + 9 * hub;
  double hx[3] = {R[0], R[3], 0.0};
  double norm = hypot(hx[0], hx[1]);
  sum[0] = sum[1] = sum[2] = 0.0;
  if (norm < 1e-9) { /* hub axis vertical: no heading, no tyre force */
    for (int k = 0; k < n; k++) {
      const double* s = e + E_act_x1 + 6 * k;
      d->ctrl[(int)s[3]] = d->ctrl[(int)s[4]] = d->ctrl[(int)s[5]] = 0.0;
    }
    return;
  }
  hx[0] /= norm;
  hx[1] /= norm;
  double hy[3] = {-hx[1], hx[0], 0.0};
  double omega_n = d->cvel[6 * hub_body + 2];
  for (int k = 0; k < n; k++) {
    const double* s = e + E_act_x1 + 6 * k;
    /* the tyre's centre: on the spin axis (the hub's y), twins either side */
    double off = n == 2 ? (k == 0 ? e[E_half_spacing] : -e[E_half_spacing]) : 0.0;
    const mjtNum* h = d->site_xpos + 3 * hub;
    double centre[3] = {h[0] + off * R[1], h[1] + off * R[4], h[2] + off * R[7]};
    double contact[3] = {centre[0], centre[1], 0.0};
    double vc[3], vg[3];
    point_velocity(d, hub_body, root, centre, vc);
    point_velocity(d, hub_body, root, contact, vg);
    double rho = p[T_r0] - centre[2];
    double Fz = rho > 0.0 ? fmax(p[T_cz] * rho - p[T_dz] * vc[2], 0.0) : 0.0;
    double rD = p[T_r0] - fmax(rho, 0.0) / 3.0; /* Rill 3.3.3: (2 r0 + r_S) / 3 */
    double vx = vg[0] * hx[0] + vg[1] * hx[1], vy = vg[0] * hy[0] + vg[1] * hy[1];
    if (trail != 0.0) vy -= trail * d->qvel[(int)e[E_steer_dof]];
    double Fx, Fy, Mz, My, dxe, dye, dpe;
    tyre(p, Fz, vx, vy, rD * d->qvel[spin], omega_n, d->act[(int)s[0]], d->act[(int)s[1]],
         d->act[(int)s[2]], &Fx, &Fy, &Mz, &My, &dxe, &dye, &dpe);
    d->ctrl[(int)s[3]] = dxe;
    d->ctrl[(int)s[4]] = dye;
    d->ctrl[(int)s[5]] = dpe;
    double F[3] = {Fx * hx[0] + Fy * hy[0], Fx * hx[1] + Fy * hy[1], Fz};
    double T[3] = {My * hy[0], My * hy[1], Mz};
    sum[0] += F[0];
    sum[1] += F[1];
    sum[2] += F[2];
    apply_ft(m, d, F, T, contact, wheel_body, d->qfrc_passive);
    if (trail != 0.0) d->qfrc_passive[(int)e[E_steer_dof]] -= trail * Fy;
  }
}

/* ------------------------------------------------------------------ block */

/* The last block this thread found valid (extensions.h). */
static __thread seen_block seen = {0};

static int ids_ok(const mjModel* m, const double* blk) {
  int ne = (int)blk[3], ns = (int)blk[4], nc = (int)blk[6];
  const double* col = blk + HEADER + ns * N_TYRE;
  for (int i = 0; i < nc; i++, col += N_COLUMN) {
    if (!id_ok(col[C_slot], m->nu) || !id_ok(col[C_steer_l_qpos], m->nq)
        || !id_ok(col[C_steer_l_dof], m->nv) || !id_ok(col[C_steer_r_qpos], m->nq)
        || !id_ok(col[C_steer_r_dof], m->nv) || !id_ok(col[C_assist_act], m->na)
        || !id_ok(col[C_assist_ctrl], m->nu))
      return 0;
    for (int k = 0; k < C_slot; k++)
      if (!isfinite(col[k])) return 0;
    if (!(col[C_i_s] > 0.0 && col[C_k_tb] >= 0.0 && col[C_play] >= 0.0
          && col[C_play_smooth] > 0.0 && col[C_assist_max] > 0.0 && col[C_assist_tau] > 0.0))
      return 0;
  }
  const double* e = blk + HEADER + ns * N_TYRE + nc * N_COLUMN;
  for (int i = 0; i < ne; i++, e += N_END) {
    if (!id_ok(e[E_hub_site], m->nsite) || !id_ok(e[E_hub_body], m->nbody)
        || !id_ok(e[E_root_body], m->nbody) || !id_ok(e[E_wheel_body], m->nbody)
        || !id_ok(e[E_spin_dof], m->nv) || !id_ok(e[E_tyre_set], ns)
        || !(e[E_n_tyres] == 1.0 || e[E_n_tyres] == 2.0) || !isfinite(e[E_half_spacing])
        || !isfinite(e[E_trail]) || (e[E_trail] != 0.0 && !id_ok(e[E_steer_dof], m->nv))
        || !isfinite(e[E_drive_share]) || !isfinite(e[E_brake_share]))
      return 0;
    for (int k = 0; k < (int)e[E_n_tyres]; k++) {
      const double* s = e + E_act_x1 + 6 * k;
      for (int j = 0; j < 3; j++)
        if (!id_ok(s[j], m->na) || !id_ok(s[3 + j], m->nu)) return 0;
    }
  }
  const double* p = blk + HEADER;
  for (int k = 0; k < ns * N_TYRE; k++)
    if (!isfinite(p[k])) return 0;
  for (int j = 0; j < ns; j++, p += N_TYRE) {
    if (!(p[T_r0] > 0.0 && p[T_cz] > 0.0 && p[T_fzn] > 0.0 && p[T_fzmax] > 0.0
          && p[T_sxm_1] > 0.0 && p[T_sym_1] > 0.0 && p[T_cx] > 0.0 && p[T_dx] > 0.0
          && p[T_cy] > 0.0 && p[T_dy] > 0.0 && p[T_cpsi] > 0.0 && p[T_dpsi] > 0.0
          && p[T_vn] > 0.0))
      return 0;
  }
  return 1;
}

/* The block of model m, or NULL when m carries none this process may follow. */
static const double* valid_block(const mjModel* m) {
  int size = 0, unused = 0;
  const mjtNum* blk = block_of(m, BLOCK_NAME, &size);
  if (blk == NULL || size < HEADER) return NULL;
  if (seen_before(&seen, m, blk, size, &unused)) return blk;
  if (!block_sealed(blk, TRUTH_ABI) || blk[5] != N_TYRE) return NULL;
  double ne = blk[3], ns = blk[4], nc = blk[6];
  if (!(ne >= 0.0 && ne <= 256.0 && ne == floor(ne) && ns >= 1.0 && ns <= 16.0
        && ns == floor(ns) && (nc == 0.0 || nc == 1.0)))
    return NULL;
  if (!((blk[H_FOLLOW] == 0.0 || blk[H_FOLLOW] == 1.0) && isfinite(blk[H_KV])
        && id_ok(blk[H_FOLLOWER], m->nu) && id_ok(blk[H_SITE], m->nsite)))
    return NULL;
  if (size != HEADER + (int)ns * N_TYRE + (int)nc * N_COLUMN + (int)ne * N_END) return NULL;
  if (block_checksum(blk + 8, size - 8) != blk[7]) return NULL;
  if (m->nuserdata < 3 * (int)ne + 1 + N_DIAG) return NULL;
  if (!ids_ok(m, blk)) return NULL;
  remember(&seen, m, blk, size, 0);
  return blk;
}

/* ------------------------------------------------------------------ exported */

/* artic_truth_abi, artic_truth_mj_version, artic_truth_set_key, artic_truth_checksum
 * (extensions.h) */
ARTIC_EXPORTS(artic_truth, TRUTH_ABI)

const char* artic_truth_tyre_names(void) { return tyre_names; }

const char* artic_truth_column_names(void) { return column_names; }

const char* artic_truth_end_names(void) { return end_names; }

int artic_truth_header(void) { return HEADER; }

int artic_truth_diagnostics(void) { return N_DIAG; }

int artic_truth_block_ok(const mjModel* m) { return valid_block(m) != NULL; }

/* Steady state at given slips, for the fit and the tests: forces [N], the
 * aligning torque travelling forward plus the bore torque [N m]. */
void artic_truth_steady(const double* p, int n, const double* Fz, const double* sx,
                        const double* sy, const double* sB, double* Fx, double* Fy, double* Mz) {
  for (int i = 0; i < n; i++) {
    if (!loaded(p, Fz[i])) {
      Fx[i] = Fy[i] = Mz[i] = 0.0;
      continue;
    }
    slip_state o;
    evaluate(p, Fz[i], sx[i], sy[i], sB[i], &o);
    double xn = sx[i] / o.hsx, yn = sy[i] / o.hsy;
    Fx[i] = o.fos * xn;
    Fy[i] = o.fos * yn;
    double n_t = o.L * trail_ratio(sy[i], o.nto0, o.synto0, o.syntoe);
    Mz[i] = -n_t * Fy[i] + o.RB * o.fos * sB[i];
  }
}

/* The dynamic tyre at given states, for the tests. */
void artic_truth_tyre(const double* p, int n, const double* Fz, const double* vx,
                      const double* vy, const double* v_roll, const double* omega_n,
                      const double* xe, const double* ye, const double* pe, double* Fx,
                      double* Fy, double* Mz, double* My, double* dxe, double* dye, double* dpe) {
  for (int i = 0; i < n; i++)
    tyre(p, Fz[i], vx[i], vy[i], v_roll[i], omega_n[i], xe[i], ye[i], pe[i], Fx + i, Fy + i,
         Mz + i, My + i, dxe + i, dye + i, dpe + i);
}

/* The column law, for the tests: out = TL, TR, dTa, box, tb, rod torque on R. */
void artic_truth_column(const double* c, double ref, double dl, double dr, double wl, double wr,
                        double Ta, double* out) {
  column_law(c, ref, dl, dr, wl, wr, Ta, out, out + 1, out + 2, out + 3);
}

/* The passive callback, reached through the plant's (artic_register_kind). */
void artic_truth_passive(const mjModel* m, mjData* d) {
  const double* blk = valid_block(m);
  if (blk == NULL) return;
  int ne = (int)blk[3], ns = (int)blk[4], nc = (int)blk[6];
  const double* sets = blk + HEADER;
  const double* col = sets + ns * N_TYRE;
  const double* e = col + nc * N_COLUMN;
  double F = 0.0, gear = 1.0;
  if (blk[H_FOLLOW] != 0.0) {
    F = follower_force(m, d, blk);
    gear = d->ctrl[(int)blk[H_FOLLOWER]] >= 0.0 ? 1.0 : -1.0; /* forward or reverse */
  }
  for (int i = 0; i < ne; i++, e += N_END) {
    const double* p = sets + (int)e[E_tyre_set] * N_TYRE;
    wheel_end(m, d, p, e, d->userdata + 3 * i);
    if (F != 0.0) { /* drive while pushing the way of travel, brakes while holding back */
      double share = F * gear >= 0.0 ? e[E_drive_share] : e[E_brake_share];
      d->qfrc_passive[(int)e[E_spin_dof]] += F * share * p[T_r0];
    }
  }
  d->userdata[3 * ne] = 0.0;
  double* diag = d->userdata + 3 * ne + 1;
  if (nc) {
    int slot = (int)col[C_slot];
    double ref = d->ctrl[slot];
    if (m->actuator_ctrllimited[slot]) {
      ref = fmax(ref, m->actuator_ctrlrange[2 * slot]);
      ref = fmin(ref, m->actuator_ctrlrange[2 * slot + 1]);
    }
    int ql = (int)col[C_steer_l_qpos], qr = (int)col[C_steer_r_qpos];
    int vl = (int)col[C_steer_l_dof], vr = (int)col[C_steer_r_dof];
    double TL, TR, dTa;
    column_law(col, ref, d->qpos[ql], d->qpos[qr], d->qvel[vl], d->qvel[vr],
               d->act[(int)col[C_assist_act]], &TL, &TR, &dTa, diag);
    d->ctrl[(int)col[C_assist_ctrl]] = dTa;
    d->qfrc_passive[vl] += TL;
    d->qfrc_passive[vr] += TR;
  } else {
    diag[0] = diag[1] = diag[2] = 0.0;
  }
}

/* ====================================================================== the yard truth
 *
 * The independent truth's own stepping loop (validation/synthetic/yardtruth.py). It
 * shares nothing with the plant under validation and installs no MuJoCo callback:
 * one call advances the truth's own MuJoCo model n steps of its own timestep,
 *
 *   mj_step1 -> tyre, steering, fifth-wheel and drive forces into qfrc_applied
 *            -> mj_step2 -> the hidden states (tyre deflections, assist) by Euler,
 *
 * and leaves the model's kinematics at the new state (for observing it). Its
 * numbers arrive as plain arrays the Python side builds (no block in the model):
 *
 *   par: [n_sets, n_ends, n_z, follow, kv_mass, tau, fifth_roll_dof, lash, lash_w,
 *         k_roll, c_roll, drive_site, drive_body, has_column, z_follow, f_drive, f_brake]
 *        then the tyre sets (TYRE_PARAMS order), the column (COLUMN_PARAMS order:
 *        its ids slot .. assist_ctrl are read as steer_l/r qpos and dofs, and
 *        assist_act as the index of the assist torque in z), then the ends (Y_END).
 *   ctl: [ref (the left-wheel angle the steering wheel stands for) [rad], u0 [m/s],
 *         u_dot [m/s^2], t0 [s] (the ramp's start), drive torque [N m] (pedals)]
 *   z:   the hidden states, read and written.
 *   out: per end the sum of its tyres' forces (3), then the column's box,
 *        torsion-bar and tie-rod torques and the fifth wheel's roll torque.
 */
#define Y_PAR 17
enum { YP_NSETS, YP_NENDS, YP_NZ, YP_FOLLOW, YP_KV, YP_TAU, YP_FROLL, YP_LASH, YP_LASHW,
       YP_KROLL, YP_CROLL, YP_DSITE, YP_DBODY, YP_COLUMN, YP_ZFOLLOW, YP_FDRIVE, YP_FBRAKE };

#define Y_END_FIELDS(X) \
  X(hub_site) X(hub_body) X(wheel_body) X(spin_dof) X(n_tyres) X(tyre_set) X(half_spacing) \
  X(trail) X(steer_dof) X(drive_share) X(brake_share) X(z_first)
#define ENUM_Y(name) Y_##name,
enum { Y_END_FIELDS(ENUM_Y) N_YEND };
static const char yard_end_names[] = Y_END_FIELDS(STR);

const char* artic_yard_end_names(void) { return yard_end_names; }

int artic_yard_header(void) { return Y_PAR; }

/* The forces of one wheel end on qfrc, its tyres' deflection rates into zdot. */
static void yard_end(const mjModel* m, const mjData* d, const double* p, const double* e,
                     const double* z, double* zdot, double* qfrc, double* sum) {
  int hub = (int)e[Y_hub_site], hub_body = (int)e[Y_hub_body];
  int wheel_body = (int)e[Y_wheel_body], spin = (int)e[Y_spin_dof], n = (int)e[Y_n_tyres];
  int z0 = (int)e[Y_z_first];
  double trail = e[Y_trail];
  const mjtNum* R = d->site_xmat + 9 * hub;
  double hx[2] = {R[0], R[3]};
  double norm = hypot(hx[0], hx[1]);
  sum[0] = sum[1] = sum[2] = 0.0;
  for (int k = 0; k < 3 * n; k++) zdot[z0 + k] = 0.0;
  if (norm < 1e-9) return;
  hx[0] /= norm;
  hx[1] /= norm;
  double hy[2] = {-hx[1], hx[0]};
  double omega_n = d->cvel[6 * hub_body + 2];
  int root = m->body_rootid[hub_body];
  for (int k = 0; k < n; k++) {
    double off = n == 2 ? (k == 0 ? e[Y_half_spacing] : -e[Y_half_spacing]) : 0.0;
    const mjtNum* h = d->site_xpos + 3 * hub;
    double centre[3] = {h[0] + off * R[1], h[1] + off * R[4], h[2] + off * R[7]};
    double contact[3] = {centre[0], centre[1], 0.0};
    double vc[3], vg[3];
    point_velocity(d, hub_body, root, centre, vc);
    point_velocity(d, hub_body, root, contact, vg);
    double rho = p[T_r0] - centre[2];
    double Fz = rho > 0.0 ? fmax(p[T_cz] * rho - p[T_dz] * vc[2], 0.0) : 0.0;
    double rD = p[T_r0] - fmax(rho, 0.0) / 3.0;
    double vx = vg[0] * hx[0] + vg[1] * hx[1], vy = vg[0] * hy[0] + vg[1] * hy[1];
    if (trail != 0.0) vy -= trail * d->qvel[(int)e[Y_steer_dof]];
    double Fx, Fy, Mz, My;
    tyre(p, Fz, vx, vy, rD * d->qvel[spin], omega_n, z[z0 + 3 * k], z[z0 + 3 * k + 1],
         z[z0 + 3 * k + 2], &Fx, &Fy, &Mz, &My, zdot + z0 + 3 * k, zdot + z0 + 3 * k + 1,
         zdot + z0 + 3 * k + 2);
    double F[3] = {Fx * hx[0] + Fy * hy[0], Fx * hx[1] + Fy * hy[1], Fz};
    double T[3] = {My * hy[0], My * hy[1], Mz};
    sum[0] += F[0];
    sum[1] += F[1];
    sum[2] += F[2];
    apply_ft(m, d, F, T, contact, wheel_body, qfrc);
    if (trail != 0.0) qfrc[(int)e[Y_steer_dof]] -= trail * Fy;
  }
}

/* The follower's force [N]: the combination's mass times the wanted acceleration,
 * plus a critically damped proportional and integral answer to the speed error at
 * the drive axle's site over the time constant tau; the error's integral is a
 * hidden state (z[z_follow]), whose rate this writes. The force is what the
 * truck's drive (f_drive, the way of travel) and brakes (f_brake) can give; while
 * it is held at either, the integral stops (no wind-up: a demand past the drive
 * would spin the driven wheels up without end). */
static double yard_follow_force(const mjModel* m, const mjData* d, const double* par,
                                double u, double u_dot, double gear, const double* z,
                                double* zdot) {
  int site = (int)par[YP_DSITE], body = (int)par[YP_DBODY], zi = (int)par[YP_ZFOLLOW];
  const mjtNum* R = d->site_xmat + 9 * site;
  double v[3];
  point_velocity(d, body, m->body_rootid[body], d->site_xpos + 3 * site, v);
  double along = (v[0] * R[0] + v[1] * R[3]) / fmax(hypot(R[0], R[3]), 1e-9);
  double tau = par[YP_TAU], e = u - along;
  double F = par[YP_KV] * (u_dot + 2.0 * e / tau + z[zi] / (tau * tau));
  double push = F * gear, lim = push >= 0.0 ? par[YP_FDRIVE] : par[YP_FBRAKE];
  zdot[zi] = e;
  if (fabs(F) > lim) {
    F = copysign(lim, F);
    if (e * F > 0.0) zdot[zi] = 0.0; /* held at the limit and asked for more */
  }
  return F;
}

static void yard_forces(const mjModel* m, const mjData* d, const double* par, const double* ctl,
                        const double* z, double* zdot, double* out) {
  int ns = (int)par[YP_NSETS], ne = (int)par[YP_NENDS], nc = (int)par[YP_COLUMN];
  const double* sets = par + Y_PAR;
  const double* col = sets + ns * N_TYRE;
  const double* e = col + nc * N_COLUMN;
  double* qfrc = d->qfrc_applied;
  memset(qfrc, 0, sizeof(mjtNum) * m->nv);
  double F = 0.0, gear = 1.0;
  if (par[YP_FOLLOW] != 0.0) {
    double u = ctl[1] + ctl[2] * (d->time - ctl[3]);
    gear = u >= 0.0 ? 1.0 : -1.0;
    F = yard_follow_force(m, d, par, u, ctl[2], gear, z, zdot);
  }
  for (int i = 0; i < ne; i++, e += N_YEND) {
    const double* p = sets + (int)e[Y_tyre_set] * N_TYRE;
    yard_end(m, d, p, e, z, zdot, qfrc, out + 3 * i);
    int spin = (int)e[Y_spin_dof];
    if (F != 0.0) { /* drive while pushing the way of travel, brakes while holding back */
      double share = F * gear >= 0.0 ? e[Y_drive_share] : e[Y_brake_share];
      qfrc[spin] += F * share * p[T_r0];
    }
    qfrc[spin] += ctl[4] * e[Y_drive_share];
  }
  /* the fifth wheel's roll: free within its lash, then its rubber bushes */
  int fr = (int)par[YP_FROLL];
  double* diag = out + 3 * ne;
  diag[0] = diag[1] = diag[2] = diag[3] = 0.0;
  if (fr >= 0) {
    int qa = m->jnt_qposadr[m->dof_jntid[fr]];
    diag[3] = -par[YP_KROLL] * dead_zone(d->qpos[qa], 0.5 * par[YP_LASH], par[YP_LASHW])
              - par[YP_CROLL] * d->qvel[fr];
    qfrc[fr] += diag[3];
  }
  if (nc) {
    int ql = (int)col[C_steer_l_qpos], qr = (int)col[C_steer_r_qpos];
    int vl = (int)col[C_steer_l_dof], vr = (int)col[C_steer_r_dof];
    int za = (int)col[C_assist_act];
    double TL, TR, dTa;
    column_law(col, ctl[0], d->qpos[ql], d->qpos[qr], d->qvel[vl], d->qvel[vr], z[za], &TL, &TR,
               &dTa, diag);
    zdot[za] = dTa;
    qfrc[vl] += TL;
    qfrc[vr] += TR;
  }
}

/* Advance n steps; returns 0, or 1 when the state stopped being finite. */
int artic_yard_advance(const mjModel* m, mjData* d, const double* par, const double* ctl,
                       double* z, double* zdot, int n, double* out) {
  int nz = (int)par[YP_NZ];
  double h = m->opt.timestep;
  for (int k = 0; k < n; k++) {
    mj_step1(m, d);
    yard_forces(m, d, par, ctl, z, zdot, out);
    mj_step2(m, d);
    for (int j = 0; j < nz; j++) z[j] += h * zdot[j];
  }
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_comVel(m, d);
  for (int j = 0; j < m->nq; j++)
    if (!isfinite(d->qpos[j])) return 1;
  for (int j = 0; j < nz; j++)
    if (!isfinite(z[j])) return 1;
  return 0;
}

/* The kinematics of the current state (after a restore). */
void artic_yard_kinematics(const mjModel* m, mjData* d) {
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_comVel(m, d);
}

/* ------------------------------------------------------------------------------------------
 * The harness's closed loop around the yard truth: a whole log in one call.
 *
 * Per sample k, what validation/harness/loop.py's Python loop does with YardTruth (and with
 * the floor's Replay of it), in the same order and the same IEEE operations, so that the
 * rows are the same to the bit (tests/test_yard_loop.py):
 *
 *   1. the feedback law on YardTruth.gamma (wrap_angle of the two sensors' headings);
 *   2. YardTruth.observe, which carries the units' unwrapped headings in psi;
 *   3. the stop: |gamma| past gamma_max, or a signal past its OBSERVATION_LIMIT (NaN too);
 *   4. YardTruth.step: the steering box's lock, the pedals (their brakes), the controls and
 *      round(dt / h) steps of artic_yard_advance. Replaying (act != NULL), the step takes the
 *      recorded row act[act_k] (steering, speed, its rate, throttle, brake) in place of the
 *      harness's demand, as Replay.step does.
 *
 * Returns YL_DONE, YL_STOPPED (n_done rows), YL_DIVERGED (artic_yard_advance's check failed
 * in the step after row n_done - 1: Python raises as YardTruth._advance does) or
 * YL_REPLAY_END (the recorded actuation ran out before that step: Python raises as
 * Replay.step does). */
#define YL_MAX_ENDS 32
enum { YL_DONE = 0, YL_STOPPED = 1, YL_DIVERGED = 4, YL_REPLAY_END = 6, YL_BAD = 5 };

typedef struct {
  int sensor_site[2], sensor_body[2];
  double eps[2];
  double gain, delta_max, gamma_max, lock;
  double obs_limit[13];
  int pedals; /* the speed mode "pedals" */
  double throttle, brake; /* the pedals as set, when no recorded row sets them */
  double drive_max, brake_max, parking, weight, r0_mean;
  int parked;
  int n_ends, spin[YL_MAX_ENDS];
  double r0[YL_MAX_ENDS], brake_share[YL_MAX_ENDS];
  const double* act; /* n_act rows of (delta, u1, u1_dot, throttle, brake), or NULL */
  int n_act;
  /* state, read and written */
  double psi[2], decel;
  int act_k, steer_limited;
} yard_loop;

int artic_yard_loop_size(void) { return (int)sizeof(yard_loop); }

static const double YL_PI = 3.14159265358979323846;

/* artic.mjcf.interface.wrap_angle's scalar path: pi - (pi - a) % (2 pi), Python's float %. */
static double yl_wrap_angle(double a) {
  double x = YL_PI - a, b = 2.0 * YL_PI;
  double mod = fmod(x, b);
  if (mod != 0.0) {
    if ((b < 0.0) != (mod < 0.0)) mod += b;
  } else {
    mod = copysign(0.0, b);
  }
  return YL_PI - mod;
}

/* Python's max(a, b) and min(a, b) on floats: the first unless the second is beyond it. */
static double py_max(double a, double b) { return b > a ? b : a; }
static double py_min(double a, double b) { return b < a ? b : a; }

static double yl_heading(const mjData* d, int site) {
  const mjtNum* R = d->site_xmat + 9 * site;
  return atan2(R[3], R[0]);
}

/* YardTruth.observe */
static void yl_observe(const mjModel* m, mjData* d, yard_loop* s, double* out) {
  double vel[6];
  for (int i = 0; i < 2; i++) {
    int site = s->sensor_site[i], body = s->sensor_body[i];
    double prev = s->psi[i];
    double psi = prev + yl_wrap_angle(yl_heading(d, site) - prev);
    s->psi[i] = psi;
    mj_objectVelocity(m, d, mjOBJ_SITE, site, vel, 0);
    double h = psi + s->eps[i];
    double c = cos(h), sn = sin(h);
    const mjtNum* B = d->xmat + 9 * body;
    const mjtNum* p = d->site_xpos + 3 * site;
    double* o = out + 6 * i;
    o[0] = p[0];
    o[1] = p[1];
    o[2] = h;
    o[3] = c * vel[3] + sn * vel[4];
    o[4] = -sn * vel[3] + c * vel[4];
    o[5] = vel[0] * B[2] + vel[1] * B[5] + vel[2] * B[8];
  }
  out[12] = yl_wrap_angle(out[2] - out[8]);
}

/* YardTruth._set_brakes */
static void yl_set_brakes(mjModel* m, yard_loop* s, double decel) {
  if (decel != s->decel) {
    for (int e = 0; e < s->n_ends; e++)
      m->dof_frictionloss[s->spin[e]] = decel * s->weight * s->r0[e] * s->brake_share[e];
    s->decel = decel;
  }
}

static int yl_sound(const mjModel* m, const yard_loop* s, const double* par) {
  if (s->n_ends < 0 || s->n_ends > YL_MAX_ENDS || (s->act == NULL && s->n_act != 0)
      || (int)par[YP_NZ] < 0) {
    return 0;
  }
  for (int i = 0; i < 2; i++)
    if (s->sensor_site[i] < 0 || s->sensor_site[i] >= m->nsite || s->sensor_body[i] < 0
        || s->sensor_body[i] >= m->nbody) {
      return 0;
    }
  for (int e = 0; e < s->n_ends; e++)
    if (s->spin[e] < 0 || s->spin[e] >= m->nv) return 0;
  return 1;
}

/* Run samples 0 .. n - 1 of a log from the truth's present state; see above. The model is
 * not const: the pedals' brakes are its spin joints' friction, as YardTruth._set_brakes. */
int artic_yard_run_loop(mjModel* m, mjData* d, const double* par, double* ctl, double* z,
                        double* zdot, double* out, yard_loop* s, int n, const double* dt,
                        const double* delta_c, const double* u1, const double* u1_dot,
                        const double* gamma_meas, const double* weight, double* obs,
                        double* delta, double* delta_fb, unsigned char* sat, int* n_done) {
  *n_done = 0;
  if (!yl_sound(m, s, par)) return YL_BAD;
  double h = m->opt.timestep;
  for (int k = 0; k < n; k++) {
    /* 1. feedback_law(delta_c, YardTruth.gamma, gamma_meas, weight, gain, delta_max) */
    double gamma = yl_wrap_angle(yl_heading(d, s->sensor_site[0]) + s->eps[0]
                                 - yl_heading(d, s->sensor_site[1]) - s->eps[1]);
    double fb = 0.0;
    if (weight[k] != 0.0) {
      double e = gamma - gamma_meas[k];
      fb = weight[k] * s->gain
           * (e - 2.0 * YL_PI * floor((e + YL_PI) / (2.0 * YL_PI)));
    }
    double dl = delta_c[k] + fb;
    unsigned char limited = 0;
    if (dl > s->delta_max) {
      dl = s->delta_max;
      limited = 1;
    } else if (dl < -s->delta_max) {
      dl = -s->delta_max;
      limited = 1;
    }
    /* 2. observe */
    double* o = obs + 13 * k;
    yl_observe(m, d, s, o);
    delta[k] = dl;
    delta_fb[k] = dl - delta_c[k];
    sat[k] = limited;
    *n_done = k + 1;
    /* 3. the stop */
    int beyond = fabs(o[12]) > s->gamma_max;
    for (int j = 0; j < 13; j++) beyond = beyond || !(fabs(o[j]) <= s->obs_limit[j]);
    if (beyond) return YL_STOPPED;
    if (k + 1 >= n) break;
    /* 4. step(dt, delta, u1, u1_dot), or Replay.step's recorded row */
    double dem = dl, u = u1[k], u_dot = u1_dot[k], throttle = s->throttle, brake = s->brake;
    if (s->act != NULL) {
      if (s->act_k >= s->n_act) return YL_REPLAY_END;
      const double* row = s->act + 5 * (size_t)s->act_k;
      dem = row[0];
      u = row[1];
      u_dot = row[2];
      throttle = s->throttle = row[3];
      brake = s->brake = row[4];
    }
    double r = nearbyint(dt[k] / h);
    int nsub = r < 1.0 ? 1 : (int)r;
    if (fabs(dem) > s->lock) {
      s->steer_limited += 1;
      dem = copysign(s->lock, dem);
    }
    double drive = 0.0;
    if (s->pedals) {
      double th = py_min(py_max(throttle, 0.0), 1.0);
      double br = py_min(py_max(brake, 0.0), 1.0);
      double gear = u >= 0.0 ? 1.0 : -1.0;
      drive = gear * th * s->drive_max * s->weight * s->r0_mean;
      yl_set_brakes(m, s, py_max(br * s->brake_max, s->parked ? s->parking : 0.0));
    }
    ctl[0] = dem;
    ctl[1] = u;
    ctl[2] = u_dot;
    ctl[3] = d->time;
    ctl[4] = drive;
    if (artic_yard_advance(m, d, par, ctl, z, zdot, nsub, out)) return YL_DIVERGED;
    if (s->act != NULL) s->act_k += 1;
  }
  return YL_DONE;
}
