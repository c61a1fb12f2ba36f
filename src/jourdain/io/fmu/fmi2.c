/* FMI 2.0 model exchange and co-simulation of a jourdain model (jourdain.io.fmu).

   The model is M(y,t)·ÿ + k(y,ẏ,t) = q(y,ẏ,t) with the continuous states x = [y; ẏ] and the
   derivatives ẋ = [ẏ; ÿ]. model.h (generated) gives the sizes, the value references, the start
   values and the tables of the reaction outputs; jd_local.c and jd_engine.c (generated) give

       int  jd_dynamics(y, yd, t, p, u, ydd, wrench)   ÿ and every joint's wrench (F, T) in the
                                                         child frame at the joint point, 0 or
                                                         1 (M not positive definite), 2 (NaN)
       void jd_dirs(y, yd, t, p, u, E)                  the constrained directions of the joints
                                                         whose reactions are outputs

   A reaction component g of a joint with constrained directions E (6×n) solves
   EᵀE·g = Eᵀ·W, W the wrench the joint transmits (for orthonormal directions g = Eᵀ·W).
   Co-simulation integrates with the Dormand–Prince 5(4) pair (rk_tables.h) under error control,
   the inputs held, or extrapolated linearly where their derivatives are set.

   A closed system (model.h defines JD_CLOSED; closed.c): the states are the independent
   coordinates y and their rates in the partition fixed at export, ÿ comes from
   jd_closed_dynamics (Newton on Φ = 0 for the dependent coordinates, the velocity map, M, k, q
   in y), and the dependent coordinates, their rates and Φ are outputs (JD_NOUT of them after
   the reactions). A singular Φ_d or a failed Newton solve is fmi2Error with a logged message. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "model.h"
#include "rk_tables.h"

#define JD_NX (2 * JD_NY)
#define JD_NP1 (JD_NP > 0 ? JD_NP : 1)
#define JD_NU1 (JD_NU > 0 ? JD_NU : 1)
#define JD_NG1 (JD_NG > 0 ? JD_NG : 1)
#define JD_NB1 (JD_NB > 0 ? JD_NB : 1)

/* value references, in this order (model.h has the counts) */
#define JD_VR_TIME 0
#define JD_VR_Y 1
#define JD_VR_YD (JD_VR_Y + JD_NY)
#define JD_VR_DY (JD_VR_YD + JD_NY)   /* der(y) = ẏ */
#define JD_VR_YDD (JD_VR_DY + JD_NY)  /* der(ẏ) = ÿ */
#define JD_VR_P (JD_VR_YDD + JD_NY)
#define JD_VR_U (JD_VR_P + JD_NP)
#define JD_VR_G (JD_VR_U + JD_NU)
#define JD_VR_OUT (JD_VR_G + JD_NG)  /* a closed system's outputs (closed.c) */
#define JD_NVR (JD_VR_OUT + JD_NOUT)
#define JD_NOUT1 (JD_NOUT > 0 ? JD_NOUT : 1)
#ifdef JD_CLOSED
#define JD_NDEP1 (JD_NDEP > 0 ? JD_NDEP : 1)
#endif

/* the states of the FMI 2.0 state machines, as bits */
enum { JD_INSTANTIATED = 1, JD_INIT = 2, JD_EVENT = 4, JD_CONT = 8, JD_STEP = 16,
       JD_TERMINATED = 32, JD_ERROR = 64 };
#define JD_ANY 127

/* everything fmi2GetFMUstate saves: plain numbers, no pointers */
typedef struct {
    double time, start_time, tolerance, h_next, du_time;
    double x[JD_NX], p[JD_NP1], u[JD_NU1], du[JD_NU1];
    double ydd[JD_NY], g[JD_NG1], out[JD_NOUT1];
#ifdef JD_CLOSED
    double z[JD_NZ], y_last[JD_NY], info[8];  /* the loop kernel's state (closed.c) */
#endif
    int mode, valid;
} jd_data;

typedef struct {
    jd_data d;
    fmi2Type type;
    int logging;
    char *name;
    fmi2CallbackFunctions cb;
#ifdef JD_CLOSED
    double *work;           /* the loop kernel's work array (jd_closed_work doubles) */
    long piv[JD_NDEP1];
#endif
} jd_instance;

#define JD_STATE_MAGIC 0x6a644d55u /* "jdMU" */

static void jd_log(const jd_instance *c, fmi2Status status, const char *category,
                   const char *fmt, ...) {
    char msg[640];
    va_list ap;
    if (!c || !c->cb.logger) return;
    if (status == fmi2OK && !c->logging) return;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    c->cb.logger(c->cb.componentEnvironment, c->name, status, category, "%s", msg);
}

static fmi2Status jd_fail(jd_instance *c, const char *fn, const char *what) {
    jd_log(c, fmi2Error, "logStatusError", "%s: %s", fn, what);
    return fmi2Error;
}

/* NULL instance, or a call the state machine does not allow: fmi2Error */
static int jd_refuse(jd_instance *c, int allowed, const char *fn) {
    if (!c) return 1;
    if (c->d.mode & allowed) return 0;
    jd_log(c, fmi2Error, "logStatusError", "%s: not allowed in the current state of the instance",
           fn);
    return 1;
}

static void jd_defaults(jd_data *d) {
    memset(d, 0, sizeof *d);
    memcpy(d->x, jd_x_start, sizeof(double) * JD_NX);
#if JD_NP
    memcpy(d->p, jd_p_start, sizeof(double) * JD_NP);
#endif
#if JD_NU
    memcpy(d->u, jd_u_start, sizeof(double) * JD_NU);
#endif
    d->tolerance = JD_DEFAULT_TOLERANCE;
    d->mode = JD_INSTANTIATED;
#ifdef JD_CLOSED
    memcpy(d->z, jd_z_start, sizeof(double) * JD_NZ);
#endif
}

/* ÿ (and the joint wrenches W of a tree, the outputs of a closed system) at a state */
static int jd_eval(jd_instance *c, const double *y, const double *yd, double t, const double *u,
                   double *ydd, double *W) {
#ifdef JD_CLOSED
    (void)W;
    return jd_closed_dynamics(c->d.z, c->d.y_last, c->d.info, c->work, c->piv, y, yd, t,
                              c->d.p, u, ydd, c->d.out);
#else
    return jd_dynamics(y, yd, t, c->d.p, u, ydd, W);
#endif
}

static const char *jd_status_text(int status) {
    if (status == 1) return "the mass matrix M is not positive definite";
    if (status == 2) return "the accelerations are not finite (NaN or inf in the model's terms)";
    if (status == 3) return "the reaction equations of a joint are singular";
    if (status == 11) return "Newton found no configuration of the dependent coordinates on "
                             "the closure Phi = 0 (Phi_d singular, or divergence)";
    if (status == 12) return "Phi_d is singular here: its condition number passed the limit "
                             "of the partition fixed at export (a singular position of the "
                             "mechanism, or one the independent coordinates cannot describe)";
    if (status == 13) return "M in the independent coordinates is not positive definite";
    if (status == 15) return "the velocity rows of the contacts are singular or redundant with "
                             "the speeds here (W = [E_z; A] singular)";
    if (status == 14) return "Newton's solution of the dependent coordinates left the branch "
                             "of the motion (a correction far beyond the first-order "
                             "prediction: near a singular position, or a step too large)";
    return "the model could not be evaluated";
}

/* reaction outputs from the joint wrenches W (6 per body) */
static int jd_reactions(const double *y, const double *yd, double t, const double *p,
                        const double *u, const double *W, double *g) {
#if JD_NG
    double E[JD_NE], gj[6 * JD_NJ];
    jd_dirs(y, yd, t, p, u, E);
    for (int j = 0; j < JD_NJ; ++j) {
        int n = jd_rj_ndir[j];
        const double *Ej = E + jd_rj_off[j], *Wb = W + 6 * jd_rj_body[j];
        double G[36], r[6], L[36];
        for (int k = 0; k < n; ++k) {
            r[k] = 0.0;
            for (int a = 0; a < 6; ++a) r[k] += Ej[6 * k + a] * Wb[a];
            for (int l = 0; l < n; ++l) {
                double s = 0.0;
                for (int a = 0; a < 6; ++a) s += Ej[6 * k + a] * Ej[6 * l + a];
                G[k * n + l] = s;
            }
        }
        /* Cholesky of the Gram matrix EᵀE, then the two triangular solves */
        for (int k = 0; k < n; ++k) {
            double d = G[k * n + k];
            for (int m = 0; m < k; ++m) d -= L[k * n + m] * L[k * n + m];
            if (!(d > 1e-12 * G[k * n + k])) return 3;
            L[k * n + k] = sqrt(d);
            for (int i = k + 1; i < n; ++i) {
                double s = G[i * n + k];
                for (int m = 0; m < k; ++m) s -= L[i * n + m] * L[k * n + m];
                L[i * n + k] = s / L[k * n + k];
            }
        }
        for (int k = 0; k < n; ++k) {
            double s = r[k];
            for (int m = 0; m < k; ++m) s -= L[k * n + m] * r[m];
            r[k] = s / L[k * n + k];
        }
        for (int k = n - 1; k >= 0; --k) {
            double s = r[k];
            for (int m = k + 1; m < n; ++m) s -= L[m * n + k] * r[m];
            r[k] = s / L[k * n + k];
        }
        for (int k = 0; k < n; ++k) gj[6 * j + k] = r[k];
    }
    for (int o = 0; o < JD_NG; ++o) g[o] = gj[6 * jd_g_joint[o] + jd_g_dir[o]];
#else
    (void)y; (void)yd; (void)t; (void)p; (void)u; (void)W; (void)g;
#endif
    return 0;
}

/* ÿ and the reaction outputs at the instance's time, states, parameters and inputs (cached
   until one of them changes) */
static int jd_update(jd_instance *c) {
    double W[6 * JD_NB1];
    int status;
    if (c->d.valid) return 0;
    status = jd_eval(c, c->d.x, c->d.x + JD_NY, c->d.time, c->d.u, c->d.ydd, W);
    if (status == 0)
        status = jd_reactions(c->d.x, c->d.x + JD_NY, c->d.time, c->d.p, c->d.u, W, c->d.g);
    if (status) {
#ifdef JD_CLOSED
        if (status > 10) {
            jd_log(c, fmi2Error, "logStatusError", "at t = %.17g: %s (condition number of "
                   "Phi_d %.3g, limit %.3g; |Phi| %.3g after %.0f Newton steps)", c->d.time,
                   jd_status_text(status), c->d.info[0], (double)JD_COND_LIMIT, c->d.info[3],
                   c->d.info[1]);
            return status;
        }
#endif
        jd_log(c, fmi2Error, "logStatusError", "at t = %.17g: %s", c->d.time,
               jd_status_text(status));
        return status;
    }
    c->d.valid = 1;
    return 0;
}

/* ---- creation, set-up, initialization ------------------------------------------------------ */
const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c_, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_ANY, "fmi2SetDebugLogging")) return fmi2Error;
    for (size_t i = 0; i < nCategories; ++i)
        if (!categories || !categories[i] || (strcmp(categories[i], "logStatusError") != 0
                                              && strcmp(categories[i], "logAll") != 0))
            return jd_fail(c, "fmi2SetDebugLogging", "unknown log category (the categories "
                           "are logStatusError and logAll)");
    c->logging = loggingOn ? 1 : 0;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn) {
    jd_instance *c;
    (void)fmuResourceLocation; (void)visible;
    if (!functions || !functions->allocateMemory || !functions->freeMemory) return NULL;
    if (!instanceName || !instanceName[0]) {
        if (functions->logger)
            functions->logger(functions->componentEnvironment, "?", fmi2Error, "logStatusError",
                              "fmi2Instantiate: an instance name is required");
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, JD_GUID) != 0) {
        if (functions->logger)
            functions->logger(functions->componentEnvironment, instanceName, fmi2Error,
                              "logStatusError", "fmi2Instantiate: the GUID %s is not this "
                              "FMU's (%s): modelDescription.xml and the binary do not belong "
                              "together", fmuGUID ? fmuGUID : "(none)", JD_GUID);
        return NULL;
    }
    if (fmuType != fmi2ModelExchange && fmuType != fmi2CoSimulation) {
        if (functions->logger)
            functions->logger(functions->componentEnvironment, instanceName, fmi2Error,
                              "logStatusError", "fmi2Instantiate: unknown fmuType %d",
                              (int)fmuType);
        return NULL;
    }
    c = (jd_instance *)functions->allocateMemory(1, sizeof(jd_instance));
    if (!c) return NULL;
    c->name = (char *)functions->allocateMemory(strlen(instanceName) + 1, 1);
    if (!c->name) {
        functions->freeMemory(c);
        return NULL;
    }
    strcpy(c->name, instanceName);
#ifdef JD_CLOSED
    c->work = (double *)functions->allocateMemory((size_t)jd_closed_work(), sizeof(double));
    if (!c->work) {
        functions->freeMemory(c->name);
        functions->freeMemory(c);
        return NULL;
    }
#endif
    c->cb = *functions;
    c->type = fmuType;
    c->logging = loggingOn ? 1 : 0;
    jd_defaults(&c->d);
    return c;
}

void fmi2FreeInstance(fmi2Component c_) {
    jd_instance *c = (jd_instance *)c_;
    fmi2CallbackFreeMemory free_memory;
    if (!c) return;
    free_memory = c->cb.freeMemory;
#ifdef JD_CLOSED
    free_memory(c->work);
#endif
    free_memory(c->name);
    free_memory(c);
}

fmi2Status fmi2SetupExperiment(fmi2Component c_, fmi2Boolean toleranceDefined,
                               fmi2Real tolerance, fmi2Real startTime,
                               fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    jd_instance *c = (jd_instance *)c_;
    (void)stopTimeDefined; (void)stopTime;
    if (jd_refuse(c, JD_INSTANTIATED, "fmi2SetupExperiment")) return fmi2Error;
    if (toleranceDefined) {
        if (!(tolerance > 0.0 && tolerance < 1.0))
            return jd_fail(c, "fmi2SetupExperiment", "the tolerance must lie in (0, 1)");
        c->d.tolerance = tolerance < 1e-14 ? 1e-14 : tolerance;
    }
    if (!isfinite(startTime)) return jd_fail(c, "fmi2SetupExperiment", "startTime not finite");
    c->d.start_time = c->d.time = startTime;
    c->d.valid = 0;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c_) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_INSTANTIATED, "fmi2EnterInitializationMode")) return fmi2Error;
    c->d.mode = JD_INIT;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c_) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_INIT, "fmi2ExitInitializationMode")) return fmi2Error;
    if (jd_update(c)) {
        c->d.mode = JD_ERROR;
        return fmi2Error;
    }
    c->d.mode = c->type == fmi2ModelExchange ? JD_EVENT : JD_STEP;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c_) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_EVENT | JD_CONT | JD_STEP | JD_ERROR, "fmi2Terminate")) return fmi2Error;
    c->d.mode = JD_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c_) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_ANY, "fmi2Reset")) return fmi2Error;
    jd_defaults(&c->d);
    return fmi2OK;
}

/* ---- values ------------------------------------------------------------------------------- */
fmi2Status fmi2GetReal(fmi2Component c_, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[]) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_ANY, "fmi2GetReal")) return fmi2Error;
    if (nvr && (!vr || !value)) return jd_fail(c, "fmi2GetReal", "NULL arguments");
    for (size_t i = 0; i < nvr; ++i) {
        fmi2ValueReference r = vr[i];
        if (r >= JD_NVR) return jd_fail(c, "fmi2GetReal", "unknown value reference");
        if (r >= JD_VR_YDD && r < JD_VR_P) {
            if (jd_update(c)) return fmi2Error;
            value[i] = c->d.ydd[r - JD_VR_YDD];
        } else if (r >= JD_VR_OUT) {
            if (jd_update(c)) return fmi2Error;
            value[i] = c->d.out[r - JD_VR_OUT];
        } else if (r >= JD_VR_G) {
            if (jd_update(c)) return fmi2Error;
            value[i] = c->d.g[r - JD_VR_G];
        } else if (r == JD_VR_TIME) {
            value[i] = c->d.time;
        } else if (r < JD_VR_DY) {
            value[i] = c->d.x[r - JD_VR_Y];
        } else if (r < JD_VR_YDD) {
            value[i] = c->d.x[JD_NY + r - JD_VR_DY];
        } else if (r < JD_VR_U) {
            value[i] = c->d.p[r - JD_VR_P];
        } else {
            value[i] = c->d.u[r - JD_VR_U];
        }
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c_, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[]) {
    jd_instance *c = (jd_instance *)c_;
    int m;
    if (jd_refuse(c, JD_INSTANTIATED | JD_INIT | JD_EVENT | JD_CONT | JD_STEP, "fmi2SetReal"))
        return fmi2Error;
    if (nvr && (!vr || !value)) return jd_fail(c, "fmi2SetReal", "NULL arguments");
    m = c->d.mode;
    for (size_t i = 0; i < nvr; ++i) {
        fmi2ValueReference r = vr[i];
        if (r >= JD_NVR) return jd_fail(c, "fmi2SetReal", "unknown value reference");
        if (!isfinite(value[i])) return jd_fail(c, "fmi2SetReal", "the value is not finite");
        if (r >= JD_VR_Y && r < JD_VR_DY) {          /* y, ẏ: initial="exact" */
            if (!(m & (JD_INSTANTIATED | JD_INIT)))
                return jd_fail(c, "fmi2SetReal", "coordinates and rates are set before or "
                               "during initialization (later: fmi2SetContinuousStates)");
            c->d.x[r - JD_VR_Y] = value[i];
        } else if (r >= JD_VR_P && r < JD_VR_U) {   /* tunable parameters */
            if (m & JD_CONT)
                return jd_fail(c, "fmi2SetReal", "tunable parameters are set in event mode, "
                               "not in continuous-time mode");
            c->d.p[r - JD_VR_P] = value[i];
        } else if (r >= JD_VR_U && r < JD_VR_G) {   /* inputs */
            c->d.u[r - JD_VR_U] = value[i];
            c->d.du[r - JD_VR_U] = 0.0;             /* a new value: its derivative is unknown */
        } else {
            return jd_fail(c, "fmi2SetReal", "the variable is computed, it cannot be set");
        }
    }
    if (nvr) c->d.valid = 0;
    return fmi2OK;
}

static fmi2Status jd_no_variables(jd_instance *c, size_t nvr, const char *fn) {
    if (jd_refuse(c, JD_ANY, fn)) return fmi2Error;
    if (nvr) return jd_fail(c, fn, "the FMU has no variables of this type");
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Integer value[]) {
    (void)vr; (void)value;
    return jd_no_variables((jd_instance *)c, nvr, "fmi2GetInteger");
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[]) {
    (void)vr; (void)value;
    return jd_no_variables((jd_instance *)c, nvr, "fmi2GetBoolean");
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[]) {
    (void)vr; (void)value;
    return jd_no_variables((jd_instance *)c, nvr, "fmi2GetString");
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[]) {
    (void)vr; (void)value;
    return jd_no_variables((jd_instance *)c, nvr, "fmi2SetInteger");
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[]) {
    (void)vr; (void)value;
    return jd_no_variables((jd_instance *)c, nvr, "fmi2SetBoolean");
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[]) {
    (void)vr; (void)value;
    return jd_no_variables((jd_instance *)c, nvr, "fmi2SetString");
}

/* ---- FMU state ---------------------------------------------------------------------------- */
fmi2Status fmi2GetFMUstate(fmi2Component c_, fmi2FMUstate *state) {
    jd_instance *c = (jd_instance *)c_;
    jd_data *s;
    if (jd_refuse(c, JD_ANY, "fmi2GetFMUstate")) return fmi2Error;
    if (!state) return jd_fail(c, "fmi2GetFMUstate", "NULL argument");
    s = (jd_data *)*state;
    if (!s) {
        s = (jd_data *)c->cb.allocateMemory(1, sizeof(jd_data));
        if (!s) return jd_fail(c, "fmi2GetFMUstate", "out of memory");
    }
    *s = c->d;
    *state = s;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c_, fmi2FMUstate state) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_ANY, "fmi2SetFMUstate")) return fmi2Error;
    if (!state) return jd_fail(c, "fmi2SetFMUstate", "NULL state");
    c->d = *(const jd_data *)state;
#ifdef JD_CLOSED
    c->d.info[4] = 0.0;  /* the kernel's prediction (J_z in its work array) is not saved */
#endif
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c_, fmi2FMUstate *state) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_ANY, "fmi2FreeFMUstate")) return fmi2Error;
    if (state && *state) {
        c->cb.freeMemory(*state);
        *state = NULL;
    }
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c_, fmi2FMUstate state, size_t *size) {
    jd_instance *c = (jd_instance *)c_;
    (void)state;
    if (jd_refuse(c, JD_ANY, "fmi2SerializedFMUstateSize")) return fmi2Error;
    if (!size) return jd_fail(c, "fmi2SerializedFMUstateSize", "NULL argument");
    *size = sizeof(unsigned) + sizeof(jd_data);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c_, fmi2FMUstate state, fmi2Byte bytes[],
                                 size_t size) {
    jd_instance *c = (jd_instance *)c_;
    unsigned magic = JD_STATE_MAGIC;
    if (jd_refuse(c, JD_ANY, "fmi2SerializeFMUstate")) return fmi2Error;
    if (!state || !bytes || size < sizeof magic + sizeof(jd_data))
        return jd_fail(c, "fmi2SerializeFMUstate", "NULL state or buffer too small");
    memcpy(bytes, &magic, sizeof magic);
    memcpy(bytes + sizeof magic, state, sizeof(jd_data));
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c_, const fmi2Byte bytes[], size_t size,
                                   fmi2FMUstate *state) {
    jd_instance *c = (jd_instance *)c_;
    unsigned magic;
    jd_data *s;
    if (jd_refuse(c, JD_ANY, "fmi2DeSerializeFMUstate")) return fmi2Error;
    if (!bytes || !state || size != sizeof magic + sizeof(jd_data))
        return jd_fail(c, "fmi2DeSerializeFMUstate", "the data is not a state of this FMU");
    memcpy(&magic, bytes, sizeof magic);
    if (magic != JD_STATE_MAGIC)
        return jd_fail(c, "fmi2DeSerializeFMUstate", "the data is not a state of this FMU");
    s = (jd_data *)*state;
    if (!s) {
        s = (jd_data *)c->cb.allocateMemory(1, sizeof(jd_data));
        if (!s) return jd_fail(c, "fmi2DeSerializeFMUstate", "out of memory");
    }
    memcpy(s, bytes + sizeof magic, sizeof(jd_data));
    *state = s;
    return fmi2OK;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c_, const fmi2ValueReference vUnknown[],
                                        size_t nUnknown, const fmi2ValueReference vKnown[],
                                        size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[]) {
    jd_instance *c = (jd_instance *)c_;
    (void)vUnknown; (void)nUnknown; (void)vKnown; (void)nKnown; (void)dvKnown; (void)dvUnknown;
    if (!c) return fmi2Error;
    return jd_fail(c, "fmi2GetDirectionalDerivative", "not provided by this FMU "
                   "(providesDirectionalDerivative=\"false\")");
}

/* ---- model exchange ----------------------------------------------------------------------- */
fmi2Status fmi2EnterEventMode(fmi2Component c_) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_EVENT | JD_CONT, "fmi2EnterEventMode")) return fmi2Error;
    c->d.mode = JD_EVENT;
    return fmi2OK;
}

fmi2Status fmi2NewDiscreteStates(fmi2Component c_, fmi2EventInfo *info) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_EVENT, "fmi2NewDiscreteStates")) return fmi2Error;
    if (!info) return jd_fail(c, "fmi2NewDiscreteStates", "NULL argument");
    /* no discrete states, no events: nothing changes */
    info->newDiscreteStatesNeeded = fmi2False;
    info->terminateSimulation = fmi2False;
    info->nominalsOfContinuousStatesChanged = fmi2False;
    info->valuesOfContinuousStatesChanged = fmi2False;
    info->nextEventTimeDefined = fmi2False;
    info->nextEventTime = 0.0;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c_) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_EVENT, "fmi2EnterContinuousTimeMode")) return fmi2Error;
    c->d.mode = JD_CONT;
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c_, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode,
                                       fmi2Boolean *terminateSimulation) {
    jd_instance *c = (jd_instance *)c_;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (jd_refuse(c, JD_CONT, "fmi2CompletedIntegratorStep")) return fmi2Error;
    if (enterEventMode) *enterEventMode = fmi2False;
    if (terminateSimulation) *terminateSimulation = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c_, fmi2Real time) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_EVENT | JD_CONT, "fmi2SetTime")) return fmi2Error;
    if (!isfinite(time)) return jd_fail(c, "fmi2SetTime", "the time is not finite");
    c->d.time = time;
    c->d.valid = 0;
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component c_, const fmi2Real x[], size_t nx) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_EVENT | JD_CONT, "fmi2SetContinuousStates")) return fmi2Error;
    if (nx != JD_NX || !x)
        return jd_fail(c, "fmi2SetContinuousStates", "expected the 2f states [y; yd]");
    for (size_t i = 0; i < nx; ++i)
        if (!isfinite(x[i])) return jd_fail(c, "fmi2SetContinuousStates", "a state is not finite");
    memcpy(c->d.x, x, sizeof(double) * JD_NX);
    c->d.valid = 0;
    return fmi2OK;
}

fmi2Status fmi2GetDerivatives(fmi2Component c_, fmi2Real dx[], size_t nx) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_INIT | JD_EVENT | JD_CONT | JD_TERMINATED | JD_ERROR,
                  "fmi2GetDerivatives")) return fmi2Error;
    if (nx != JD_NX || !dx) return jd_fail(c, "fmi2GetDerivatives", "expected 2f derivatives");
    if (jd_update(c)) return fmi2Error;
    memcpy(dx, c->d.x + JD_NY, sizeof(double) * JD_NY);
    memcpy(dx + JD_NY, c->d.ydd, sizeof(double) * JD_NY);
    return fmi2OK;
}

fmi2Status fmi2GetEventIndicators(fmi2Component c_, fmi2Real z[], size_t ni) {
    jd_instance *c = (jd_instance *)c_;
    (void)z;
    if (jd_refuse(c, JD_ANY, "fmi2GetEventIndicators")) return fmi2Error;
    if (ni != 0) return jd_fail(c, "fmi2GetEventIndicators", "the FMU has no event indicators");
    return fmi2OK;
}

fmi2Status fmi2GetContinuousStates(fmi2Component c_, fmi2Real x[], size_t nx) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_ANY, "fmi2GetContinuousStates")) return fmi2Error;
    if (nx != JD_NX || !x) return jd_fail(c, "fmi2GetContinuousStates", "expected 2f states");
    memcpy(x, c->d.x, sizeof(double) * JD_NX);
    return fmi2OK;
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c_, fmi2Real nominal[], size_t nx) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_ANY, "fmi2GetNominalsOfContinuousStates")) return fmi2Error;
    if (nx != JD_NX || !nominal)
        return jd_fail(c, "fmi2GetNominalsOfContinuousStates", "expected 2f states");
    for (size_t i = 0; i < nx; ++i) nominal[i] = 1.0;
    return fmi2OK;
}

/* ---- co-simulation ------------------------------------------------------------------------ */
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c_, const fmi2ValueReference vr[],
                                       size_t nvr, const fmi2Integer order[],
                                       const fmi2Real value[]) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_INSTANTIATED | JD_INIT | JD_STEP, "fmi2SetRealInputDerivatives"))
        return fmi2Error;
    for (size_t i = 0; i < nvr; ++i) {
        if (vr[i] < JD_VR_U || vr[i] >= JD_VR_G)
            return jd_fail(c, "fmi2SetRealInputDerivatives", "not an input");
        if (order[i] != 1)
            return jd_fail(c, "fmi2SetRealInputDerivatives", "only first derivatives (order 1) "
                           "are used: the inputs are extrapolated linearly over a step");
        if (!isfinite(value[i]))
            return jd_fail(c, "fmi2SetRealInputDerivatives", "the value is not finite");
        c->d.du[vr[i] - JD_VR_U] = value[i];
    }
    return fmi2OK;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c_, const fmi2ValueReference vr[],
                                        size_t nvr, const fmi2Integer order[],
                                        fmi2Real value[]) {
    jd_instance *c = (jd_instance *)c_;
    (void)vr; (void)order; (void)value;
    if (jd_refuse(c, JD_ANY, "fmi2GetRealOutputDerivatives")) return fmi2Error;
    if (!nvr) return fmi2OK;
    return jd_fail(c, "fmi2GetRealOutputDerivatives", "not provided by this FMU "
                   "(maxOutputDerivativeOrder=\"0\")");
}

/* ẋ = [ẏ; ÿ] with the inputs u0 + du·(t − t0) */
static int jd_rhs(jd_instance *c, double t, const double *x, double t0, double *dx) {
    double u[JD_NU1] = {0.0}, W[6 * JD_NB1];
    for (int i = 0; i < JD_NU; ++i) u[i] = c->d.u[i] + c->d.du[i] * (t - t0);
    memcpy(dx, x + JD_NY, sizeof(double) * JD_NY);
    return jd_eval(c, x, x + JD_NY, t, u, dx + JD_NY, W);
}

/* from t0 to t1 by Dormand–Prince 5(4) steps under error control: the weighted RMS of the
   error estimate at most 1 with the weights atol + rtol·|x| (atol = rtol/100, the ratio of
   jourdain's defaults 1e-10 / 1e-8) */
static int jd_integrate(jd_instance *c, double t0, double t1) {
    double K[7][JD_NX], xs[JD_NX], xn[JD_NX], *x = c->d.x;
    double rtol = c->d.tolerance, atol = 1e-2 * c->d.tolerance, t = t0;
    double h = c->d.h_next > 0.0 ? c->d.h_next : (t1 - t0);
    int status, rejected = 0;
    long steps = 0;
    if ((status = jd_rhs(c, t, x, t0, K[0]))) return status;
    while (t < t1) {
        double hs = h, err = 0.0, fac;
        int last = 0;
        if (t + hs >= t1 - 1e-13 * fabs(t1)) {
            hs = t1 - t;
            last = 1;
        }
        for (int s = 1; s < 6; ++s) {
            for (int i = 0; i < JD_NX; ++i) {
                double acc = 0.0;
                for (int j = 0; j < s; ++j) acc += RK5_A[7 * s + j] * K[j][i];
                xs[i] = x[i] + hs * acc;
            }
            if ((status = jd_rhs(c, t + RK5_C[s] * hs, xs, t0, K[s]))) return status;
        }
        /* the new point, and the seventh evaluation there (first of the next step: FSAL) */
        for (int i = 0; i < JD_NX; ++i) {
            double acc = 0.0;
            for (int j = 0; j < 6; ++j) acc += RK5_B[j] * K[j][i];
            xn[i] = x[i] + hs * acc;
        }
        if ((status = jd_rhs(c, t + hs, xn, t0, K[6]))) return status;
        for (int i = 0; i < JD_NX; ++i) {
            double e = 0.0, sc;
            for (int j = 0; j < 7; ++j) e += RK5_E[j] * K[j][i];
            sc = atol + rtol * fmax(fabs(x[i]), fabs(xn[i]));
            e = hs * e / sc;
            err += e * e;
        }
        err = sqrt(err / JD_NX);
        if (!isfinite(err)) return 2;
        if (err <= 1.0) {
            t = last ? t1 : t + hs;
            memcpy(x, xn, sizeof xn);
            memcpy(K[0], K[6], sizeof K[0]);
            fac = err > 0.0 ? fmin(10.0, 0.9 * pow(err, -0.2)) : 10.0;
            if (rejected) fac = fmin(1.0, fac);
            if (!last || hs >= h) h = hs * fac;
            rejected = 0;
        } else {
            h = hs * fmax(0.2, 0.9 * pow(err, -0.2));
            rejected = 1;
            if (h < 1e-14 * fmax(1.0, fabs(t))) return 4;
        }
        if (++steps > 100000000L) return 5;
    }
    c->d.h_next = h;
    return 0;
}

fmi2Status fmi2DoStep(fmi2Component c_, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    jd_instance *c = (jd_instance *)c_;
    double t0 = currentCommunicationPoint, h = communicationStepSize;
    int status;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (jd_refuse(c, JD_STEP, "fmi2DoStep")) return fmi2Error;
    if (c->type != fmi2CoSimulation)
        return jd_fail(c, "fmi2DoStep", "the instance is not a co-simulation instance");
    if (!(h >= 0.0) || !isfinite(h))
        return jd_fail(c, "fmi2DoStep", "the communication step size must be >= 0");
    if (fabs(t0 - c->d.time) > 1e-9 * fmax(1.0, fabs(t0)))
        return jd_fail(c, "fmi2DoStep", "currentCommunicationPoint is not the FMU's time");
    if (h == 0.0) return fmi2OK;
    status = jd_integrate(c, t0, t0 + h);
    if (status) {
        jd_log(c, fmi2Error, "logStatusError", "fmi2DoStep from t = %.17g: %s", t0,
               status == 4 ? "the step size fell below the round-off of t" :
               status == 5 ? "too many steps" : jd_status_text(status));
        c->d.mode = JD_ERROR;
        return fmi2Error;
    }
    /* the inputs of the new time: the master sets them (and their derivatives) anew */
    for (int i = 0; i < JD_NU; ++i) c->d.u[i] += c->d.du[i] * h;
    c->d.time = t0 + h;
    c->d.valid = 0;
    if (jd_update(c)) {
        c->d.mode = JD_ERROR;
        return fmi2Error;
    }
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c_) {
    jd_instance *c = (jd_instance *)c_;
    if (!c) return fmi2Error;
    return jd_fail(c, "fmi2CancelStep", "fmi2DoStep never returns fmi2Pending here");
}

fmi2Status fmi2GetStatus(fmi2Component c_, const fmi2StatusKind s, fmi2Status *value) {
    jd_instance *c = (jd_instance *)c_;
    (void)s;
    if (jd_refuse(c, JD_ANY, "fmi2GetStatus")) return fmi2Error;
    if (value) *value = fmi2OK;
    return fmi2Discard;  /* only meaningful after fmi2Pending, which this FMU never returns */
}

fmi2Status fmi2GetRealStatus(fmi2Component c_, const fmi2StatusKind s, fmi2Real *value) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_ANY, "fmi2GetRealStatus")) return fmi2Error;
    if (s == fmi2LastSuccessfulTime && value) {
        *value = c->d.time;
        return fmi2OK;
    }
    return fmi2Discard;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c_, const fmi2StatusKind s, fmi2Integer *value) {
    jd_instance *c = (jd_instance *)c_;
    (void)s; (void)value;
    if (jd_refuse(c, JD_ANY, "fmi2GetIntegerStatus")) return fmi2Error;
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c_, const fmi2StatusKind s, fmi2Boolean *value) {
    jd_instance *c = (jd_instance *)c_;
    if (jd_refuse(c, JD_ANY, "fmi2GetBooleanStatus")) return fmi2Error;
    if (s == fmi2Terminated && value) {
        *value = fmi2False;
        return fmi2OK;
    }
    return fmi2Discard;
}

fmi2Status fmi2GetStringStatus(fmi2Component c_, const fmi2StatusKind s, fmi2String *value) {
    jd_instance *c = (jd_instance *)c_;
    (void)s; (void)value;
    if (jd_refuse(c, JD_ANY, "fmi2GetStringStatus")) return fmi2Error;
    return fmi2Discard;
}
