/* The plant's tyre forces as MuJoCo's passive callback, in C.
 *
 * The same equations as plant/tyre.py (the reference) and the wheel
 * kinematics of plant/plant.py, term by term and in the same order, so the
 * two agree to rounding. The callback takes everything it needs from the
 * model itself: the numeric "artic.tyre" (numeric 0) holds the tyre
 * coefficients and, per wheel end, the ids of its hub site, bodies, spin dof
 * and tread actuators. Models without that block get no force from here.
 * There is no global state, so any number of models and threads can share
 * the callback, including mujoco.batch's copies of a model.
 *
 * Per wheel end the callback writes the tread deflection rates to the tread
 * actuators' ctrl and the contact force [N] to d->userdata[3 i .. 3 i + 2].
 * It counts, in d->userdata[3 n_wheels], evaluations of a loaded wheel outside
 * the property file's ranges of Fz, kappa and alpha; Python resets the count.
 */
#include <math.h>
#include <string.h>

#include <mujoco/mujoco.h>

#define ARTIC_ABI 1
#define BLOCK_NAME "artic.tyre"
#define HEADER 6   /* abi, n_wheels, R0, k_t, c_t, n_params */
#define PER_WHEEL 11

/* Coefficient order of the block; plant/ctyre.py reads it from artic_param_names(). */
#define PARAMS(X) \
  X(UNLOADED_RADIUS) X(FNOMIN) X(LONGVL) X(VXLOW) X(FZMIN) X(LFZO) \
  X(LCX) X(LEX) X(LKX) X(LHX) X(LVX) X(LMUX) X(LCY) X(LEY) X(LKY) X(LHY) X(LVY) X(LMUY) \
  X(LXAL) X(LYKA) X(LVYKA) X(LMY) X(LSGKP) X(LSGAL) \
  X(PCX1) X(PDX1) X(PDX2) X(PEX1) X(PEX2) X(PEX3) X(PEX4) X(PKX1) X(PKX2) X(PKX3) \
  X(PHX1) X(PHX2) X(PVX1) X(PVX2) X(RBX1) X(RBX2) X(RCX1) X(REX1) X(REX2) X(RHX1) \
  X(PTX1) X(PTX2) X(PTX3) X(PTX4) \
  X(PCY1) X(PDY1) X(PDY2) X(PEY1) X(PEY2) X(PEY3) X(PKY1) X(PKY2) X(PHY1) X(PHY2) \
  X(PVY1) X(PVY2) X(RBY1) X(RBY2) X(RBY3) X(RCY1) X(REY1) X(REY2) X(RHY1) X(RHY2) \
  X(RVY1) X(RVY2) X(RVY4) X(RVY5) X(RVY6) X(PTY1) X(PTY2) \
  X(QSY1) X(QSY3) X(QSY4) X(FZMAX) X(KPUMIN) X(KPUMAX) X(ALPMIN) X(ALPMAX) X(FILE_SIDE)

#define ENUM(name) name,
enum { PARAMS(ENUM) N_PARAMS };
#define STR(name) #name ","
static const char param_names[] = PARAMS(STR);

static const double PI = 3.14159265358979323846;

static double sign(double x) { return (x > 0.0) - (x < 0.0); }

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
  return shift == 0.0 ? g(B, C, E, x) : g(B, C, E, x + shift) / g(B, C, E, shift);
}

/* cos(atan(x)) and sin(2 atan(x)), without the trigonometry */
static double cos_atan(double x) { return 1.0 / sqrt(1.0 + x * x); }

static double sin_2atan(double x) { return 2.0 * x / (1.0 + x * x); }

static double fz0(const double* p) { return p[FNOMIN] * p[LFZO]; }

static double sigma_alpha(const double* p, double Fz) {
  return p[PTY1] * sin_2atan(Fz / (p[PTY2] * fz0(p))) * p[UNLOADED_RADIUS] * p[LFZO]
         * p[LSGAL];
}

static double sigma_kappa(const double* p, double Fz) {
  double Fz0 = fz0(p), dfz = (Fz - Fz0) / Fz0;
  return Fz * (p[PTX1] + p[PTX2] * dfz) * (p[PTX3] == 0.0 ? 1.0 : exp(-p[PTX3] * dfz))
         * p[UNLOADED_RADIUS] / Fz0
         * p[LSGKP];
}

static double cornering_stiffness(const double* p, double Fz) {
  double Fz0 = fz0(p);
  return fabs(p[PKY1] * Fz0 * sin_2atan(Fz / (p[PKY2] * Fz0)) * p[LFZO] * p[LKY]);
}

/* Steady-state forces, PAC2002 at zero camber (tyre.forces). */
static void forces(const double* p, double Fz, double kappa, double alpha, double side,
                   double* Fx_out, double* Fy_out) {
  Fz = fmax(Fz, 0.0);
  double s = side * p[FILE_SIDE];
  double a = -s * alpha, k = kappa;
  double Fz0 = fz0(p), dfz = (Fz - Fz0) / Fz0;
  /* longitudinal, pure slip */
  double SHx = (p[PHX1] + p[PHX2] * dfz) * p[LHX];
  double kx = k + SHx;
  double Cx = p[PCX1] * p[LCX];
  double Dx = (p[PDX1] + p[PDX2] * dfz) * p[LMUX] * Fz;
  double Ex = fmin((p[PEX1] + p[PEX2] * dfz + p[PEX3] * dfz * dfz)
                   * (1.0 - p[PEX4] * sign(kx)) * p[LEX], 1.0);
  double Kx = Fz * (p[PKX1] + p[PKX2] * dfz) * (p[PKX3] == 0.0 ? 1.0 : exp(p[PKX3] * dfz))
              * p[LKX];
  double Bx = Kx / (Cx * Dx != 0.0 ? Cx * Dx : 1.0);
  double SVx = Fz * (p[PVX1] + p[PVX2] * dfz) * p[LVX] * p[LMUX];
  double Fx0 = mf(Bx, Cx, Dx, Ex, kx) + SVx;
  /* lateral, pure slip */
  double SHy = (p[PHY1] + p[PHY2] * dfz) * p[LHY];
  double ay = a + SHy;
  double Cy = p[PCY1] * p[LCY];
  double muy = (p[PDY1] + p[PDY2] * dfz) * p[LMUY];
  double Dy = muy * Fz;
  double Ey = fmin((p[PEY1] + p[PEY2] * dfz) * (1.0 - p[PEY3] * sign(ay)) * p[LEY], 1.0);
  double Ky = p[PKY1] * Fz0 * sin_2atan(Fz / (p[PKY2] * Fz0)) * p[LFZO] * p[LKY];
  double By = Ky / (Cy * Dy != 0.0 ? Cy * Dy : 1.0);
  double SVy = Fz * (p[PVY1] + p[PVY2] * dfz) * p[LVY] * p[LMUY];
  double Fy0 = mf(By, Cy, Dy, Ey, ay) + SVy;
  /* combined slip */
  double Bxa = p[RBX1] * cos_atan(p[RBX2] * k) * p[LXAL];
  double Gxa = weight(Bxa, p[RCX1], p[REX1] + p[REX2] * dfz, a, p[RHX1]);
  double Byk = p[RBY1] * cos_atan(p[RBY2] * (a - p[RBY3])) * p[LYKA];
  double Gyk = weight(Byk, p[RCY1], p[REY1] + p[REY2] * dfz, k, p[RHY1] + p[RHY2] * dfz);
  double DVyk = muy * Fz * (p[RVY1] + p[RVY2] * dfz) * cos_atan(p[RVY4] * a);
  double SVyk = DVyk == 0.0 ? 0.0 : DVyk * sin(p[RVY5] * atan(p[RVY6] * k)) * p[LVYKA];
  *Fx_out = Gxa * Fx0;
  *Fy_out = s * (Gyk * Fy0 + SVyk);
}

/* One wheel end: deflection rates, transient forces and rolling resistance.
 * Returns 1 when a loaded wheel is outside the file's ranges. */
static int wheel(const double* p, double Fz, double Vx, double Vsx, double Vy, double u,
                 double v, double side, double* Fx, double* Fy, double* My, double* du,
                 double* dv) {
  double Fzc = fmax(Fz, p[FZMIN]);
  double sk = sigma_kappa(p, Fzc), sa = sigma_alpha(p, Fzc), ax = fabs(Vx);
  double kappa = u / sk, alpha = atan(v / sa);
  /* tyre.deflection_rates */
  *du = -Vsx - ax * u / sk;
  *dv = -Vy - ax * v / sa;
  /* tyre.transient_forces */
  forces(p, Fz, kappa, alpha, side, Fx, Fy);
  double fade = ax < p[VXLOW] ? 0.5 * (1.0 + cos(PI * ax / p[VXLOW])) : 0.0;
  double Kx = fmax(Fz, 0.0) * p[PKX1] * p[LKX];
  double Ky = cornering_stiffness(p, fmax(Fz, 0.0));
  *Fx = *Fx - fade * p[PTX4] * Kx / sk * Vsx * 0.25;
  *Fy = *Fy - fade * p[PTX4] * Ky / sa * Vy * 0.25;
  /* tyre.rolling_resistance, v_smooth = 0.05 m/s */
  double Fzp = fmax(Fz, 0.0), vr = ax / p[LONGVL];
  double mag = p[UNLOADED_RADIUS] * Fzp * (p[QSY1] + p[QSY3] * vr + p[QSY4] * (vr * vr) * (vr * vr))
               * p[LMY];
  *My = -mag * tanh(Vx / 0.05);
  return Fz > 0.0 && (Fz < p[FZMIN] || Fz > p[FZMAX] || kappa < p[KPUMIN] || kappa > p[KPUMAX]
                      || alpha < p[ALPMIN] || alpha > p[ALPMAX]);
}

/* ------------------------------------------------------------------ exported */

int artic_abi(void) { return ARTIC_ABI; }

int artic_mj_version(void) { return mjVERSION_HEADER; }

const char* artic_param_names(void) { return param_names; }

int artic_n_params(void) { return N_PARAMS; }

/* Evaluate n wheel states (for tests against the numpy reference). */
void artic_tyre_eval(const double* p, int n, const double* Fz, const double* Vx,
                     const double* Vsx, const double* Vy, const double* u, const double* v,
                     const double* side, double* Fx, double* Fy, double* My, double* du,
                     double* dv) {
  for (int i = 0; i < n; i++) {
    wheel(p, Fz[i], Vx[i], Vsx[i], Vy[i], u[i], v[i], side[i], Fx + i, Fy + i, My + i, du + i,
          dv + i);
  }
}

/* MuJoCo passive callback (mjfGeneric). */
void artic_passive(const mjModel* m, mjData* d) {
  if (m->nnumeric < 1 || strcmp(m->names + m->name_numericadr[0], BLOCK_NAME) != 0) return;
  const mjtNum* blk = m->numeric_data + m->numeric_adr[0];
  if ((int)blk[0] != ARTIC_ABI || (int)blk[5] != N_PARAMS) return;
  int nw = (int)blk[1];
  double R0 = blk[2], k_t = blk[3], c_t = blk[4];
  const double* p = blk + HEADER;
  const double* w = p + N_PARAMS;
  if (m->nuserdata < 3 * nw + 1) return;
  int outside = 0;
  for (int i = 0; i < nw; i++, w += PER_WHEEL) {
    int hub = (int)w[0], hub_body = (int)w[1], root = (int)w[2], wheel_body = (int)w[3];
    int spin = (int)w[4], act_u = (int)w[5], act_v = (int)w[6], ctrl_u = (int)w[7];
    int ctrl_v = (int)w[8];
    double n = w[9], side = w[10];
    const mjtNum* pos = d->site_xpos + 3 * hub;
    const mjtNum* R = d->site_xmat + 9 * hub;
    double hx[3] = {R[0], R[3], 0.0};
    double norm = sqrt(hx[0] * hx[0] + hx[1] * hx[1] + hx[2] * hx[2]);
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
    double Fx, Fy, My, du, dv;
    outside += wheel(p, Fz, Vx, Vsx, Vy, d->act[act_u], d->act[act_v], side, &Fx, &Fy, &My, &du,
                     &dv);
    d->ctrl[ctrl_u] = du;
    d->ctrl[ctrl_v] = dv;
    double F[3], torque[3], point[3] = {pos[0], pos[1], 0.0};
    for (int j = 0; j < 3; j++) {
      F[j] = n * Fx * hx[j] + n * Fy * hy[j];
      torque[j] = n * My * hy[j];
    }
    F[2] += n * Fz;
    d->userdata[3 * i] = F[0];
    d->userdata[3 * i + 1] = F[1];
    d->userdata[3 * i + 2] = F[2];
    mj_applyFT(m, d, F, torque, point, wheel_body, d->qfrc_passive);
  }
  d->userdata[3 * nw] += outside;
}
