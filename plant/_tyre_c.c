/* The plant's tyre forces and moments as MuJoCo's passive callback, in C.
 *
 * The same equations as plant/tyre.py (the reference) and the wheel
 * kinematics of plant/plant.py, term by term and in the same order, so the
 * two agree to rounding. The callback takes everything it needs from the
 * model itself: the numeric "artic.tyre" (numeric 0) holds a header, one or
 * more tyre coefficient sets (one per tyre file: steer, drive and trailer
 * tyres may differ) and, per wheel end, the ids of its hub site, bodies, spin
 * dof and tread actuators and its coefficient set. Models without that block
 * get no force from here; so does a block that is not sealed with this
 * process's key (plant/ctyre.py writes it), or that does not match the model
 * it sits in: a foreign or damaged block is never followed. The only mutable
 * state is each thread's copy of the last block it found valid (valid_block),
 * so any number of models and threads can share the callback, including
 * mujoco.batch's copies of a model.
 *
 * A model whose numeric 0 has another name that a compiled extension registered
 * (artic_register_kind: a second callback kind, such as the synthetic truth's
 * own tyres and steering) is handed to that extension's callback, with no
 * Python in between; this file knows nothing of what it computes.
 *
 * Per wheel end the callback writes the tread deflection rates to the tread
 * actuators' ctrl and the contact force [N] to d->userdata[3 i .. 3 i + 2].
 * It counts, in d->userdata[3 n_wheels], evaluations of a loaded wheel outside
 * the property file's ranges of Fz, kappa and alpha; Python resets the count.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include <mujoco/mujoco.h>

#include "extensions.h" /* mjcf/: the sealed block's key, checksum and memory */

#define ARTIC_ABI 3
#define BLOCK_NAME "artic.tyre"
/* abi, key_hi, key_lo, n_wheels, n_params, n_sets, moments, spin_fit, checksum */
#define HEADER 9
#define PER_WHEEL 13
#define MAX_TYRES_PER_END 4 /* ctyre.MAX_TYRES_PER_END */

/* Coefficient order of a set; plant/ctyre.py reads it from artic_param_names(). */
#define PARAMS(X) \
  X(UNLOADED_RADIUS) X(VERTICAL_STIFFNESS) X(VERTICAL_DAMPING) X(FNOMIN) X(LONGVL) X(VXLOW) \
  X(FZMIN) X(LFZO) \
  X(LCX) X(LEX) X(LKX) X(LHX) X(LVX) X(LMUX) X(LCY) X(LEY) X(LKY) X(LHY) X(LVY) X(LMUY) \
  X(LXAL) X(LYKA) X(LVYKA) X(LMY) X(LSGKP) X(LSGAL) X(LTR) X(LRES) X(LS) \
  X(PCX1) X(PDX1) X(PDX2) X(PEX1) X(PEX2) X(PEX3) X(PEX4) X(PKX1) X(PKX2) X(PKX3) \
  X(PHX1) X(PHX2) X(PVX1) X(PVX2) X(RBX1) X(RBX2) X(RCX1) X(REX1) X(REX2) X(RHX1) \
  X(PTX1) X(PTX2) X(PTX3) X(PTX4) \
  X(PCY1) X(PDY1) X(PDY2) X(PEY1) X(PEY2) X(PEY3) X(PKY1) X(PKY2) X(PHY1) X(PHY2) \
  X(PVY1) X(PVY2) X(RBY1) X(RBY2) X(RBY3) X(RCY1) X(REY1) X(REY2) X(RHY1) X(RHY2) \
  X(RVY1) X(RVY2) X(RVY4) X(RVY5) X(RVY6) X(PTY1) X(PTY2) \
  X(QSY1) X(QSY2) X(QSY3) X(QSY4) \
  X(QBZ1) X(QBZ2) X(QBZ3) X(QBZ9) X(QBZ10) X(QCZ1) X(QDZ1) X(QDZ2) X(QDZ6) X(QDZ7) \
  X(QEZ1) X(QEZ2) X(QEZ3) X(QEZ4) X(QHZ1) X(QHZ2) X(SSZ1) X(SSZ2) \
  X(FZMAX) X(KPUMIN) X(KPUMAX) X(ALPMIN) X(ALPMAX)

#define ENUM(name) name,
enum { PARAMS(ENUM) N_PARAMS };
#define STR(name) #name ","
static const char param_names[] = PARAMS(STR);

static const double PI = 3.14159265358979323846;
static const double EPS = 1e-6;          /* tyre.EPS */
static const double V_SIGN = 0.05;       /* tyre.V_SIGN */
static const double TWIST_STIFFNESS = 1.33;  /* tyre.TWIST_STIFFNESS */
static const double TWIST_LIMIT = 2.5;   /* tyre.TWIST_LIMIT */
static const double TWIST_MIN = 1e-3;    /* tyre.TWIST_MIN */
static const double PATCH_MIN = 0.02;    /* tyre.PATCH_MIN */
static const double TINY = 1e-12;        /* floor of every divisor the data could zero */

static double sign(double x) { return (x > 0.0) - (x < 0.0); }

static double sgn1(double x) { return x >= 0.0 ? 1.0 : -1.0; } /* sgn(0) = 1, the book's */

static double nz(double x) { return fabs(x) > TINY ? x : (x < 0.0 ? -TINY : TINY); }

static double mf(double B, double C, double D, double E, double x) {
  double bx = B * x;
  return D * sin(C * atan(bx - E * (bx - atan(bx))));
}

static double g(double B, double C, double E, double z) {
  double bz = B * z;
  return cos(C * atan(bz - E * (bz - atan(bz))));
}

static double weight(double B, double C, double E, double x, double shift) {
  /* g(0) = cos(0) = 1 exactly: most files have no shift */
  return shift == 0.0 ? g(B, C, E, x) : g(B, C, E, x + shift) / nz(g(B, C, E, shift));
}

/* cos(atan(x)) and sin(2 atan(x)), without the trigonometry */
static double cos_atan(double x) { return 1.0 / sqrt(1.0 + x * x); }

static double sin_2atan(double x) { return 2.0 * x / (1.0 + x * x); }

static double fz0(const double* p) { return nz(p[FNOMIN] * p[LFZO]); }

static double sigma_alpha(const double* p, double Fz) {
  return nz(p[PTY1] * sin_2atan(Fz / nz(p[PTY2] * fz0(p))) * p[UNLOADED_RADIUS] * p[LFZO]
            * p[LSGAL]);
}

static double sigma_kappa(const double* p, double Fz) {
  double Fz0 = fz0(p), dfz = (Fz - Fz0) / Fz0;
  return nz(Fz * (p[PTX1] + p[PTX2] * dfz) * (p[PTX3] == 0.0 ? 1.0 : exp(-p[PTX3] * dfz))
            * p[UNLOADED_RADIUS] / Fz0 * p[LSGKP]);
}

static double cornering_stiffness(const double* p, double Fz) {
  double Fz0 = fz0(p);
  return fabs(p[PKY1] * Fz0 * sin_2atan(Fz / nz(p[PKY2] * Fz0)) * p[LKY]);
}

static double patch_half_length(const double* p, double Fz) {
  return fmax(sqrt(p[UNLOADED_RADIUS] * fmax(Fz, 0.0) / nz(p[VERTICAL_STIFFNESS])), PATCH_MIN);
}

/* Steady-state forces and aligning moment, PAC2002 at zero camber (tyre.steady_state). */
static void steady_state(const double* p, double Fz, double kappa, double alpha,
                         double v_sign, int moments, double* Fx_out, double* Fy_out,
                         double* Mz_out) {
  Fz = fmax(Fz, 0.0);
  double a = -alpha, k = kappa;
  double ta = tan(a), ca = cos(a);
  double Fz0 = fz0(p), dfz = (Fz - Fz0) / Fz0;
  /* longitudinal, pure slip */
  double SHx = (p[PHX1] + p[PHX2] * dfz) * p[LHX];
  double kx = k + SHx;
  double Cx = p[PCX1] * p[LCX];
  double Dx = (p[PDX1] + p[PDX2] * dfz) * p[LMUX] * Fz;
  double Ex = fmin((p[PEX1] + p[PEX2] * dfz + p[PEX3] * dfz * dfz)
                   * (1.0 - p[PEX4] * sgn1(kx)) * p[LEX], 1.0);
  double Kx = Fz * (p[PKX1] + p[PKX2] * dfz) * (p[PKX3] == 0.0 ? 1.0 : exp(p[PKX3] * dfz))
              * p[LKX];
  double Bx = Kx / (Cx * Dx != 0.0 ? Cx * Dx : 1.0);
  double SVx = Fz * (p[PVX1] + p[PVX2] * dfz) * p[LVX] * p[LMUX];
  double Fx0 = mf(Bx, Cx, Dx, Ex, kx) + SVx;
  /* lateral, pure slip, at alpha* = tan(alpha) */
  double SHy = (p[PHY1] + p[PHY2] * dfz) * p[LHY];
  double ay = ta + SHy;
  double Cy = p[PCY1] * p[LCY];
  double muy = (p[PDY1] + p[PDY2] * dfz) * p[LMUY];
  double Dy = muy * Fz;
  double Ey = fmin((p[PEY1] + p[PEY2] * dfz) * (1.0 - p[PEY3] * sgn1(ay)) * p[LEY], 1.0);
  double Ky = p[PKY1] * Fz0 * sin_2atan(Fz / nz(p[PKY2] * Fz0)) * p[LKY];
  double By = Ky / (Cy * Dy != 0.0 ? Cy * Dy : 1.0);
  double SVy = Fz * (p[PVY1] + p[PVY2] * dfz) * p[LVY] * p[LMUY];
  double Fy0 = mf(By, Cy, Dy, Ey, ay) + SVy;
  /* combined slip */
  double Bxa = p[RBX1] * cos_atan(p[RBX2] * k) * p[LXAL];
  double Gxa = weight(Bxa, p[RCX1], p[REX1] + p[REX2] * dfz, ta, p[RHX1]);
  double Byk = p[RBY1] * cos_atan(p[RBY2] * (ta - p[RBY3])) * p[LYKA];
  double Gyk = weight(Byk, p[RCY1], p[REY1] + p[REY2] * dfz, k, p[RHY1] + p[RHY2] * dfz);
  double DVyk = muy * Fz * (p[RVY1] + p[RVY2] * dfz) * cos_atan(p[RVY4] * ta);
  double SVyk = DVyk == 0.0 ? 0.0 : DVyk * sin(p[RVY5] * atan(p[RVY6] * k)) * p[LVYKA];
  double Fx = Gxa * Fx0, Fy = Gyk * Fy0 + SVyk;
  *Fx_out = Fx;
  *Fy_out = Fy;
  if (!moments) { /* the plant without its tyre moments: no aligning moment to compute */
    *Mz_out = 0.0;
    return;
  }
  /* aligning moment */
  double Kyp = Ky + EPS * (Ky < 0.0 ? -1.0 : 1.0);
  double SHt = p[QHZ1] + p[QHZ2] * dfz;
  double SHf = SHy + SVy / Kyp;
  double a_t = ta + SHt, a_r = ta + SHf;
  double kk = (Kx / Kyp) * (Kx / Kyp) * k * k;
  double at_eq = sqrt(a_t * a_t + kk) * sgn1(a_t);
  double ar_eq = sqrt(a_r * a_r + kk) * sgn1(a_r);
  double lmuy = nz(p[LMUY]);
  double Bt = (p[QBZ1] + p[QBZ2] * dfz + p[QBZ3] * dfz * dfz) * p[LKY] / lmuy;
  double Ct = p[QCZ1];
  double Dt = Fz * (p[UNLOADED_RADIUS] / Fz0) * (p[QDZ1] + p[QDZ2] * dfz) * p[LTR] * v_sign;
  double Et = fmin((p[QEZ1] + p[QEZ2] * dfz + p[QEZ3] * dfz * dfz)
                   * (1.0 + p[QEZ4] * (2.0 / PI) * atan(Bt * Ct * a_t)), 1.0);
  double bt = Bt * at_eq;
  double trail = Dt * cos(Ct * atan(bt - Et * (bt - atan(bt)))) * ca;
  double Br = p[QBZ9] * p[LKY] / lmuy + p[QBZ10] * By * Cy;
  double Dr = Fz * p[UNLOADED_RADIUS] * (p[QDZ6] + p[QDZ7] * dfz) * p[LRES] * p[LMUY] * v_sign
              * ca;
  double Mzr = Dr * cos_atan(Br * ar_eq);
  double s_arm = p[UNLOADED_RADIUS] * (p[SSZ1] + p[SSZ2] * (Fy / Fz0)) * p[LS];
  *Mz_out = -trail * (Gyk * Fy0) + Mzr + s_arm * Fx;
}

/* TyreParams.twist_scale, for a load already at least FZMIN and its patch half-length */
static double twist_scale(const double* p, double Fzc, double a) {
  double Fz0 = fz0(p), dfz = (Fzc - Fz0) / Fz0;
  double mu = (p[PDY1] + p[PDY2] * dfz) * p[LMUY];
  return fmax((2.0 / 3.0) * mu * a / TWIST_STIFFNESS, TWIST_MIN);
}

/* tyre.bore_torque's friction torque M_max; the torque is M_max tanh(phi / phi_s) */
static double bore_max(const double* p, double Fz) {
  Fz = fmax(Fz, 0.0);
  double Fz0 = fz0(p), dfz = (Fz - Fz0) / Fz0;
  double mu = fmax((p[PDY1] + p[PDY2] * dfz) * p[LMUY], 0.0);
  return (2.0 / 3.0) * mu * Fz * patch_half_length(p, Fz);
}

/* One wheel end: deflection rates, transient forces and moments, rolling resistance.
 * Returns 1 when a loaded wheel is outside the file's ranges. */
static int wheel(const double* p, double Fz, double Vx, double Vsx, double Vy, double omega_z,
                 double u, double v, double phi, int moments, double* Fx, double* Fy,
                 double* Mz, double* My, double* du, double* dv, double* dphi, double* k_x,
                 double* c_x, double* b_x) {
  double Fzc = fmax(Fz, p[FZMIN]);
  double sk = sigma_kappa(p, Fzc), sa = sigma_alpha(p, Fzc), ax = fabs(Vx);
  double kappa = u / sk, alpha = atan(v / sa);
  double a = patch_half_length(p, Fzc), phi_s = twist_scale(p, Fzc, a);
  /* tyre.deflection_rates, tyre.twist_rate */
  *du = -Vsx - ax * u / sk;
  *dv = -Vy - ax * v / sa;
  *dphi = -omega_z - fabs(omega_z) * phi / (TWIST_LIMIT * phi_s) - ax * phi / a;
  /* tyre.transient_forces */
  double v_sign = tanh(Vx / V_SIGN); /* the smoothed sign of travel */
  steady_state(p, Fz, kappa, alpha, v_sign, moments, Fx, Fy, Mz);
  double vxlow = p[VXLOW] > 0.0 ? p[VXLOW] : TINY;
  double fade = ax < vxlow ? 0.5 * (1.0 + cos(PI * ax / vxlow)) : 0.0;
  double Fzp = fmax(Fz, 0.0);
  double Kx = Fzp * p[PKX1] * p[LKX];
  double Ky = cornering_stiffness(p, Fzp);
  *Fx = *Fx - fade * p[PTX4] * Kx / sk * Vsx * 0.25;
  *Fy = *Fy - fade * p[PTX4] * Ky / sa * Vy * 0.25;
  *k_x = Kx / sk;
  *c_x = fade * p[PTX4] * Kx / sk * 0.25;
  *b_x = ax / sk;
  if (moments) { /* bore torque, and the damper on the twist's elastic rate */
    double th = tanh(phi / phi_s);
    double elastic = (1.0 - th * th) * *dphi;
    *Mz = *Mz + bore_max(p, Fz) * th + fade * p[PTX4] * TWIST_STIFFNESS * Fzp * elastic * 0.25;
  } else {
    *Mz = 0.0;
  }
  /* tyre.rolling_resistance */
  double vr = ax / nz(p[LONGVL]);
  double mag = p[UNLOADED_RADIUS] * Fzp
               * (p[QSY1] + p[QSY2] * *Fx / fz0(p) + p[QSY3] * vr + p[QSY4] * (vr * vr) * (vr * vr))
               * p[LMY];
  *My = -mag * v_sign;
  return Fz > 0.0 && (Fz < p[FZMIN] || Fz > p[FZMAX] || kappa < p[KPUMIN] || kappa > p[KPUMAX]
                      || alpha < p[ALPMIN] || alpha > p[ALPMAX]);
}

/* ------------------------------------------------------------------ the spin mode */

/* spinmode.fit, term by term: the additions to a wheel end's F_x [N per tyre] and
 * du/dt [m/s] that make the integrator see g(h J) f instead of the rate f of
 * the wheel-spin/tread mode, g(z) = 1 / (1 + (z / scale)^4). Nothing for h or
 * scale 0, or where det(1 + P^4) < DET_MIN (spinmode.DET_MIN). */
static const double DET_MIN = 0.5; /* spinmode.DET_MIN */

void artic_spin_fit(double h, double scale, double inv_inertia, double q_x, double n,
                    double Re, double k, double c, double b, double f_spin, double f_u,
                    double* dFx, double* ddu) {
  *dFx = 0.0;
  *ddu = 0.0;
  if (!(scale > 0.0 && h > 0.0)) return;
  double g = q_x * n * inv_inertia;
  double s = h / scale;
  double p0 = s * g * c * Re, p1 = s * g * k, p2 = s * Re, p3 = -s * b; /* P = s J */
  double w0 = s * f_spin, w1 = s * f_u;
  for (int i = 0; i < 3; i++) { /* P^3 s f */
    double t0 = p0 * w0 + p1 * w1, t1 = p2 * w0 + p3 * w1;
    w0 = t0;
    w1 = t1;
  }
  double q0 = p0 * p0 + p1 * p2, q1 = p0 * p1 + p1 * p3; /* P^2 */
  double q2 = p2 * p0 + p3 * p2, q3 = p2 * p1 + p3 * p3;
  double n0 = 1.0 + q0 * q0 + q1 * q2, n1 = q0 * q1 + q1 * q3; /* 1 + P^4 */
  double n2 = q2 * q0 + q3 * q2, n3 = 1.0 + q2 * q1 + q3 * q3;
  double det = n0 * n3 - n1 * n2;
  if (!(det > DET_MIN)) return;
  double y0 = -(n3 * w0 - n1 * w1) / det, y1 = -(-n2 * w0 + n0 * w1) / det;
  *dFx = c * Re * y0 + k * y1;
  *ddu = Re * y0 - b * y1;
}

/* The torque about the subtree centre of mass of body's root, T + (point - c) x F,
 * the rotational part of the wrench MuJoCo's cdof act on. */
static void torque_about_com(const mjModel* m, const mjData* d, const double F[3],
                             const double T[3], const double point[3], int body, double tc[3]) {
  const mjtNum* c = d->subtree_com + 3 * m->body_rootid[body];
  double o[3] = {point[0] - c[0], point[1] - c[1], point[2] - c[2]};
  tc[0] = T[0] + o[1] * F[2] - o[2] * F[1];
  tc[1] = T[1] + o[2] * F[0] - o[0] * F[2];
  tc[2] = T[2] + o[0] * F[1] - o[1] * F[0];
}

/* Column j of J' [F; T]: cdof_rot . tc + cdof_lin . F. */
static double cdof_dot(const mjData* d, int j, const double tc[3], const double F[3]) {
  const mjtNum* sd = d->cdof + 6 * j;
  return sd[0] * tc[0] + sd[1] * tc[1] + sd[2] * tc[2] + sd[3] * F[0] + sd[4] * F[1]
         + sd[5] * F[2];
}

/* The generalized force on dof j of the force F and torque T at point on body's chain. */
static double dof_ft(const mjModel* m, const mjData* d, const double F[3], const double T[3],
                     const double point[3], int body, int j) {
  double tc[3];
  torque_about_com(m, d, F, T, point, body, tc);
  return cdof_dot(d, j, tc, F);
}

/* The force of actuator a now, as mj_fwdActuation will compute it (gain and bias
 * fixed or affine; others count zero). */
static double actuator_now(const mjModel* m, const mjData* d, int a) {
  int out = m->actuator_outadr[a];
  double input;
  if (m->actuator_dyntype[a] == mjDYN_NONE) {
    input = d->ctrl[a];
    if (m->actuator_ctrllimited[a] && !(m->opt.disableflags & mjDSBL_CLAMPCTRL))
      input = fmin(fmax(input, m->actuator_ctrlrange[2 * a]), m->actuator_ctrlrange[2 * a + 1]);
  } else {
    input = d->act[m->actuator_actadr[a] + m->actuator_actnum[a] - 1];
  }
  const mjtNum* gp = m->actuator_gainprm + mjNGAIN * a;
  const mjtNum* bp = m->actuator_biasprm + mjNBIAS * a;
  double len = d->actuator_length[out], vel = d->actuator_velocity[out], gain, bias = 0.0;
  if (m->actuator_gaintype[a] == mjGAIN_FIXED) gain = gp[0];
  else if (m->actuator_gaintype[a] == mjGAIN_AFFINE) gain = gp[0] + gp[1] * len + gp[2] * vel;
  else return 0.0;
  if (m->actuator_biastype[a] == mjBIAS_AFFINE) bias = bp[0] + bp[1] * len + bp[2] * vel;
  else if (m->actuator_biastype[a] != mjBIAS_NONE) return 0.0;
  double f = gain * input + bias;
  if (m->actuator_forcelimited[a])
    f = fmin(fmax(f, m->actuator_forcerange[2 * a]), m->actuator_forcerange[2 * a + 1]);
  return f;
}

/* Into q[nv]: the generalized force on every dof from the actuators on a joint
 * (the drive and the brakes on a wheel's spin; the tread states' actuators have
 * no gain), as mj_fwdActuation will compute it. One pass over the actuators. */
static void joint_actuator_forces(const mjModel* m, const mjData* d, mjtNum* q) {
  mju_zero(q, m->nv);
  for (int a = 0; a < m->nu; a++) {
    int t = m->actuator_trntype[a];
    if (t == mjTRN_JOINT || t == mjTRN_JOINTINPARENT)
      q[m->jnt_dofadr[m->actuator_trnid[2 * a]]] +=
          m->actuator_gear[6 * m->actuator_outadr[a]] * actuator_now(m, d, a);
  }
}

/* qfrc += J' [F; T], J the Jacobian of `point` on `body`: mj_applyFT's sum, taken
 * along the body's chain of dofs. MuJoCo's cdof are motions about the root's
 * subtree centre of mass c, so column j gives cdof_lin . F + cdof_rot . (T + (p - c) x F).
 * It skips mj_applyFT's two dense 3 x nv Jacobians per wheel: a fifth of the
 * callback's time. */
static void apply_ft(const mjModel* m, const mjData* d, const double F[3], const double T[3],
                     const double point[3], int body, mjtNum* qfrc) {
  while (body > 0 && m->body_dofnum[body] == 0) body = m->body_parentid[body];
  if (body <= 0) return;
  double tc[3];
  torque_about_com(m, d, F, T, point, body, tc);
  for (int j = m->body_dofadr[body] + m->body_dofnum[body] - 1; j >= 0; j = m->dof_parentid[j])
    qfrc[j] += cdof_dot(d, j, tc, F);
}

/* ------------------------------------------------------------------ block */

/* The last block this thread found valid (extensions.h). */
static __thread seen_block seen = {0};

/* The block of model m, or NULL when m carries none this process may follow. */
static const double* valid_block(const mjModel* m, const mjData* d, int* nw_out) {
  int size = 0;
  const mjtNum* blk = block_of(m, BLOCK_NAME, &size);
  if (blk == NULL || size < HEADER || d == NULL) return NULL;
  if (seen_before(&seen, m, blk, size, nw_out)) return blk;
  if (!block_sealed(blk, ARTIC_ABI) || blk[4] != N_PARAMS) return NULL;
  double nw_d = blk[3], ns_d = blk[5];
  if (!(nw_d >= 0.0 && nw_d <= 4096.0 && ns_d >= 1.0 && ns_d <= 64.0)) return NULL;
  int nw = (int)nw_d, ns = (int)ns_d;
  if (size != HEADER + ns * N_PARAMS + nw * PER_WHEEL) return NULL;
  if (!(blk[7] >= 0.0 && isfinite(blk[7]))) return NULL; /* spin_fit */
  if (block_checksum(blk + HEADER, size - HEADER) != blk[8]) return NULL;
  if (m->nuserdata < 3 * nw + 1 || d == NULL) return NULL;
  const double* w = blk + HEADER + ns * N_PARAMS;
  for (int i = 0; i < nw; i++, w += PER_WHEEL) {
    if (!id_ok(w[0], m->nsite) || !id_ok(w[1], m->nbody) || !id_ok(w[2], m->nbody)
        || !id_ok(w[3], m->nbody) || !id_ok(w[4], m->nv) || !id_ok(w[5], m->na)
        || !id_ok(w[6], m->na) || !id_ok(w[7], m->na) || !id_ok(w[8], m->nu)
        || !id_ok(w[9], m->nu) || !id_ok(w[10], m->nu) || !id_ok(w[12], ns)
        || !(w[11] > 0.0 && w[11] <= MAX_TYRES_PER_END)) {
      return NULL;
    }
  }
  remember(&seen, m, blk, size, nw);
  *nw_out = nw;
  return blk;
}

/* ------------------------------------------------------------------ other kinds */

/* Callbacks of other compiled extensions, by the name of the numeric 0 their
 * models carry. Registered once per process before any of their models steps;
 * an entry is never changed or removed, so reading the table needs no lock. */
#define MAX_KINDS 8
#define KIND_NAME 64
typedef void (*artic_kind_fn)(const mjModel*, mjData*);
static struct {
  char name[KIND_NAME];
  artic_kind_fn fn;
} kinds[MAX_KINDS];
static int n_kinds = 0;

static artic_kind_fn kind_of(const mjModel* m) {
  if (m->nnumeric < 1) return NULL;
  const char* name = m->names + m->name_numericadr[0];
  for (int i = 0; i < n_kinds; i++)
    if (strcmp(name, kinds[i].name) == 0) return kinds[i].fn;
  return NULL;
}

/* ------------------------------------------------------------------ exported */

/* Serve models whose numeric 0 is named `name` with `fn`. Returns its index, the
 * existing one for a name registered before (the first fn stays), or -1 when
 * the name is the plant's own, too long, or the table is full. */
int artic_register_kind(const char* name, artic_kind_fn fn) {
  if (name == NULL || fn == NULL || strlen(name) >= KIND_NAME || strcmp(name, BLOCK_NAME) == 0)
    return -1;
  for (int i = 0; i < n_kinds; i++)
    if (strcmp(name, kinds[i].name) == 0) return i;
  if (n_kinds >= MAX_KINDS) return -1;
  strcpy(kinds[n_kinds].name, name);
  kinds[n_kinds].fn = fn;
  return n_kinds++;
}

/* artic_abi, artic_mj_version, artic_set_key, artic_checksum (extensions.h) */
ARTIC_EXPORTS(artic, ARTIC_ABI)

const char* artic_param_names(void) { return param_names; }

int artic_n_params(void) { return N_PARAMS; }

int artic_header(void) { return HEADER; }

int artic_per_wheel(void) { return PER_WHEEL; }

/* 1 when m's block is one the callback follows (for Python's checks). */
int artic_block_ok(const mjModel* m, const mjData* d) {
  int nw = 0;
  return valid_block(m, d, &nw) != NULL;
}

/* Evaluate n wheel states (for tests against the numpy reference). */
void artic_tyre_eval(const double* p, int n, int moments, const double* Fz, const double* Vx,
                     const double* Vsx, const double* Vy, const double* omega_z, const double* u,
                     const double* v, const double* phi, double* Fx, double* Fy, double* Mz,
                     double* My, double* du, double* dv, double* dphi) {
  for (int i = 0; i < n; i++) {
    double k_x, c_x, b_x;
    wheel(p, Fz[i], Vx[i], Vsx[i], Vy[i], omega_z[i], u[i], v[i], phi[i], moments, Fx + i,
          Fy + i, Mz + i, My + i, du + i, dv + i, dphi + i, &k_x, &c_x, &b_x);
  }
}

/* MuJoCo passive callback (mjfGeneric). */
void artic_passive(const mjModel* m, mjData* d) {
  int nw = 0;
  const mjtNum* blk = valid_block(m, d, &nw);
  if (blk == NULL) {
    artic_kind_fn other = kind_of(m);
    if (other != NULL) other(m, d);
    return;
  }
  int moments = blk[6] != 0.0;
  double fit_scale = blk[7], h = m->opt.timestep;
  /* The spin's other generalized forces for the fit: MuJoCo's own passive
   * force, the applied force and the joints' actuators (artic_spin_fit). */
  mj_markStack(d);
  mjtNum* q_other = NULL;
  if (fit_scale > 0.0) {
    q_other = mj_stackAllocNum(d, m->nv);
    joint_actuator_forces(m, d, q_other);
  }
  const double* sets = blk + HEADER;
  const double* w = sets + (int)blk[5] * N_PARAMS;
  int outside = 0;
  for (int i = 0; i < nw; i++, w += PER_WHEEL) {
    int hub = (int)w[0], hub_body = (int)w[1], root = (int)w[2], wheel_body = (int)w[3];
    int spin = (int)w[4], act_u = (int)w[5], act_v = (int)w[6], act_w = (int)w[7];
    int ctrl_u = (int)w[8], ctrl_v = (int)w[9], ctrl_w = (int)w[10];
    double n = w[11];
    const double* p = sets + (int)w[12] * N_PARAMS;
    double R0 = p[UNLOADED_RADIUS], k_t = p[VERTICAL_STIFFNESS], c_t = p[VERTICAL_DAMPING];
    const mjtNum* pos = d->site_xpos + 3 * hub;
    const mjtNum* R = d->site_xmat + 9 * hub;
    double hx[3] = {R[0], R[3], 0.0};
    double norm = sqrt(hx[0] * hx[0] + hx[1] * hx[1]);
    double F[3] = {0.0, 0.0, 0.0};
    if (norm < 1e-9) { /* hub axis vertical: no heading, no tyre force */
      d->userdata[3 * i] = d->userdata[3 * i + 1] = d->userdata[3 * i + 2] = 0.0;
      d->ctrl[ctrl_u] = d->ctrl[ctrl_v] = d->ctrl[ctrl_w] = 0.0;
      continue;
    }
    hx[0] /= norm;
    hx[1] /= norm;
    double hy[3] = {-hx[1], hx[0], 0.0};
    const mjtNum* cvel = d->cvel + 6 * hub_body;
    const mjtNum* com = d->subtree_com + 3 * root;
    double r[3] = {pos[0] - com[0], pos[1] - com[1], pos[2] - com[2]};
    const mjtNum *om = cvel, *v0 = cvel + 3;
    double vel[3] = {v0[0] + (om[1] * r[2] - om[2] * r[1]),
                     v0[1] + (om[2] * r[0] - om[0] * r[2]),
                     v0[2] + (om[0] * r[1] - om[1] * r[0])};
    double rho = R0 - pos[2];
    double Fz = rho > 0.0 ? k_t * rho - c_t * vel[2] : 0.0;
    Fz = fmax(Fz, 0.0);
    double Vx = vel[0] * hx[0] + vel[1] * hx[1] + vel[2] * hx[2];
    double Vy = vel[0] * hy[0] + vel[1] * hy[1] + vel[2] * hy[2];
    double Re = R0 - fmax(rho, 0.0) / 3.0;
    double Vsx = Vx - d->qvel[spin] * Re;
    double Fx, Fy, Mz, My, du, dv, dphi, k_x, c_x, b_x;
    outside += wheel(p, Fz, Vx, Vsx, Vy, om[2], d->act[act_u], d->act[act_v], d->act[act_w],
                     moments, &Fx, &Fy, &Mz, &My, &du, &dv, &dphi, &k_x, &c_x, &b_x);
    double torque[3], point[3] = {pos[0], pos[1], 0.0};
    for (int j = 0; j < 3; j++) {
      F[j] = n * Fx * hx[j] + n * Fy * hy[j];
      torque[j] = n * My * hy[j];
    }
    F[2] += n * Fz;
    torque[2] += n * Mz;
    /* the spin mode, fitted to the step (spinmode); a braked spin is MuJoCo's
     * friction constraint's, which the solver holds implicitly */
    if (fit_scale > 0.0 && m->dof_frictionloss[spin] == 0.0) {
      double zero[3] = {0.0, 0.0, 0.0};
      double inv_I = m->dof_invweight0[spin];
      double q_x = dof_ft(m, d, hx, zero, point, wheel_body, spin);
      double f_spin = (dof_ft(m, d, F, torque, point, wheel_body, spin) + q_other[spin]
                       + d->qfrc_passive[spin] + d->qfrc_applied[spin]) * inv_I;
      double dFx, ddu;
      artic_spin_fit(h, fit_scale, inv_I, q_x, n, Re, k_x, c_x, b_x, f_spin, du, &dFx, &ddu);
      Fx += dFx;
      du += ddu;
      for (int j = 0; j < 3; j++) F[j] += n * dFx * hx[j];
    }
    d->ctrl[ctrl_u] = du;
    d->ctrl[ctrl_v] = dv;
    d->ctrl[ctrl_w] = dphi;
    d->userdata[3 * i] = F[0];
    d->userdata[3 * i + 1] = F[1];
    d->userdata[3 * i + 2] = F[2];
    apply_ft(m, d, F, torque, point, wheel_body, d->qfrc_passive);
  }
  mj_freeStack(d);
  d->userdata[3 * nw] += outside;
}

/* A clock that always reads zero, for mjcb_time. The Python bindings install a
 * timer that reads the system clock at every stage of every step (about 5 % of
 * the plant's step); the artic command sets this one instead (runtime.py). */
double artic_zero_clock(void) { return 0.0; }
