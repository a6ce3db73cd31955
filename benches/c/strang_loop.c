/* The Strang splitting of the free rigid body and of the heavy top as a C programmer would write
 * it (issue 28's reference loop): the same flows as lieflow's `splitting` (the rotations about the
 * two non-reference principal axes, the Casimir turn about M for the attitude, the kick of the
 * potential), the first and last half flows of consecutive steps fused, the same short sin/cos
 * polynomial (Taylor to r^17 / r^16), the attitude as a unit quaternion renormalised every 256
 * steps; one body alone, or a batch laid out component by component in blocks of 64 bodies that
 * the compiler vectorises (SoA). Built and run by benches/python/c_loop.py:
 *
 *     cc -O3 -march=native [-fopenmp] strang_loop.c -o strang_loop -lm
 *     strang_loop SYSTEM ATTITUDE BODIES STEPS THREADS
 *
 * SYSTEM: rigid (I = (1, 2, 3)) or heavy (I = (1, 2, 3), mgl = 0.7, chi = (0.2, -0.3, 1));
 * ATTITUDE: 0 or 1; dt = 0.01. Prints the seconds of the stepping and, for body 0, M (and Gamma)
 * and the attitude as a rotation matrix, for the comparison with lieflow's result.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static const double S[8] = {-1.0 / 6.0,          1.0 / 120.0,          -1.0 / 5040.0,
                            1.0 / 362880.0,      -1.0 / 39916800.0,    1.0 / 6227020800.0,
                            -1.0 / 1307674368000.0, 1.0 / 355687428096000.0};
static const double C[7] = {1.0 / 24.0,          -1.0 / 720.0,          1.0 / 40320.0,
                            -1.0 / 3628800.0,    1.0 / 479001600.0,     -1.0 / 87178291200.0,
                            1.0 / 20922789888000.0};

/* P(z), Q(z) with sin r = r + r z P, cos r = 1 - z/2 + z^2 Q, z = r^2. */
static inline void pq(double z, double *p, double *q) {
    double z2 = z * z, z4 = z2 * z2;
    *p = (S[0] + S[1] * z) + (S[2] + S[3] * z) * z2 + ((S[4] + S[5] * z) + (S[6] + S[7] * z) * z2) * z4;
    *q = (C[0] + C[1] * z) + (C[2] + C[3] * z) * z2 + ((C[4] + C[5] * z) + C[6] * z2) * z4;
}

/* sin r and cos r - 1 for |r| <= 0.78 (the angles of a step). */
static inline void sin_cosm1(double r, double *s, double *cm1) {
    double z = r * r, p, q;
    pq(z, &p, &q);
    *s = r + r * z * p;
    *cm1 = z * z * q - 0.5 * z;
}

typedef struct {
    double m[3], g[3], q[4];
} Body;

static const double I[3] = {1.0, 2.0, 3.0};
/* The reference axis is the middle moment (index 1); the axis flows turn about e2 and e0. */
static const int AX[2] = {2, 0};
static double COEF[2];
static const double MGL = 0.7, CHI[3] = {0.2, -0.3, 1.0};

/* q <- q (x) (w, v). */
static inline void qmul(double *q, double w, const double *v) {
    double a = q[0], b = q[1], c = q[2], d = q[3];
    q[0] = a * w - b * v[0] - c * v[1] - d * v[2];
    q[1] = a * v[0] + b * w + c * v[2] - d * v[1];
    q[2] = a * v[1] - b * v[2] + c * w + d * v[0];
    q[3] = a * v[2] + b * v[1] - c * v[0] + d * w;
}

/* Axis flow a over time tau: M (and Gamma) turned about e_k by -theta, theta = tau a_k M_k; the
 * attitude by q <- q (x) (cos(theta/2), sin(theta/2) e_k). */
static inline void axis(Body *b, int a, double tau, int heavy, int att) {
    int k = AX[a], i = (k + 1) % 3, j = (k + 2) % 3;
    double th = tau * COEF[a] * b->m[k], s, cm1;
    sin_cosm1(th, &s, &cm1);
    double mi = b->m[i], mj = b->m[j];
    b->m[i] = mi + (cm1 * mi + s * mj);
    b->m[j] = mj + (cm1 * mj - s * mi);
    if (heavy) {
        double gi = b->g[i], gj = b->g[j];
        b->g[i] = gi + (cm1 * gi + s * gj);
        b->g[j] = gj + (cm1 * gj - s * gi);
    }
    if (att) {
        double hs, hcm1, v[3] = {0, 0, 0};
        sin_cosm1(0.5 * th, &hs, &hcm1);
        v[k] = hs;
        qmul(b->q, 1.0 + hcm1, v);
    }
}

/* Casimir flow over tau: Gamma <- exp(-v^) Gamma, q <- q (x) exp(v/2), v = tau M / I_r. */
static inline void casimir(Body *b, double tau, int heavy, int att) {
    double t = tau / I[1];
    double v[3] = {t * b->m[0], t * b->m[1], t * b->m[2]};
    double th2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2], p, q;
    if (heavy) {
        pq(th2, &p, &q);
        double A = 1.0 + th2 * p, B = 0.5 - th2 * q; /* sin th / th, (1 - cos th) / th^2 */
        double *x = b->g;
        double w[3] = {v[1] * x[2] - v[2] * x[1], v[2] * x[0] - v[0] * x[2], v[0] * x[1] - v[1] * x[0]};
        double u[3] = {v[1] * w[2] - v[2] * w[1], v[2] * w[0] - v[0] * w[2], v[0] * w[1] - v[1] * w[0]};
        for (int k = 0; k < 3; k++) x[k] += B * u[k] - A * w[k];
    }
    if (att) {
        double z = 0.25 * th2; /* (th/2)^2 */
        pq(z, &p, &q);
        double sinc = 1.0 + z * p, c = 1.0 - 0.5 * z + z * z * q;
        double h[3] = {0.5 * sinc * v[0], 0.5 * sinc * v[1], 0.5 * sinc * v[2]};
        qmul(b->q, c, h);
    }
}

/* Kick over tau: M <- M + tau Gamma x c. */
static double CVEC[3]; /* c = mgl chi / |chi|, as lieflow's HeavyTop */
static inline void kick(Body *b, double tau) {
    const double *c = CVEC, *g = b->g;
    b->m[0] += tau * (g[1] * c[2] - g[2] * c[1]);
    b->m[1] += tau * (g[2] * c[0] - g[0] * c[2]);
    b->m[2] += tau * (g[0] * c[1] - g[1] * c[0]);
}

static inline void renormalise(double *q) {
    double n = 1.0 / sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (int k = 0; k < 4; k++) q[k] *= n;
}

/* `steps` Strang steps of one body, outer flows fused: the first flow's half step at each end. */
static void run(Body *b, long steps, double h, int heavy, int att) {
    double h2 = 0.5 * h;
    if (heavy) {
        kick(b, h2);
        for (long n = 0; n < steps; n++) {
            axis(b, 0, h2, 1, att);
            axis(b, 1, h2, 1, att);
            casimir(b, h, 1, att);
            axis(b, 1, h2, 1, att);
            axis(b, 0, h2, 1, att);
            kick(b, n + 1 < steps ? h : h2);
            if (att && (n & 255) == 255) renormalise(b->q);
        }
    } else if (att) {
        axis(b, 0, h2, 0, 1);
        for (long n = 0; n < steps; n++) {
            axis(b, 1, h2, 0, 1);
            casimir(b, h, 0, 1);
            axis(b, 1, h2, 0, 1);
            axis(b, 0, n + 1 < steps ? h : h2, 0, 1);
            if ((n & 255) == 255) renormalise(b->q);
        }
    } else {
        axis(b, 0, h2, 0, 0);
        for (long n = 0; n < steps; n++) {
            axis(b, 1, h, 0, 0);
            axis(b, 0, n + 1 < steps ? h : h2, 0, 0);
        }
    }
}

/* The batch laid out component by component (SoA) in blocks of BLOCK bodies stepped together
 * through all the steps, each flow a loop over the block that the compiler vectorises: the same
 * operations per body as `run`. */
#define BLOCK 64
typedef struct {
    double m[3][BLOCK], g[3][BLOCK], q[4][BLOCK];
} Block;

/* The axis flow about e_K ((I, J, K) cyclic) on a block, K a constant of each instance. */
#define AXIS_SOA(NAME, K, I, J)                                                                 \
    static inline void NAME(Block *restrict b, double tc, int heavy, int att, int n) {          \
        _Pragma("omp simd") for (int l = 0; l < n; l++) {                                       \
            double th = tc * b->m[K][l], s, cm1;                                                \
            sin_cosm1(th, &s, &cm1);                                                            \
            double mi = b->m[I][l], mj = b->m[J][l];                                            \
            b->m[I][l] = mi + (cm1 * mi + s * mj);                                              \
            b->m[J][l] = mj + (cm1 * mj - s * mi);                                              \
            if (heavy) {                                                                        \
                double gi = b->g[I][l], gj = b->g[J][l];                                        \
                b->g[I][l] = gi + (cm1 * gi + s * gj);                                          \
                b->g[J][l] = gj + (cm1 * gj - s * gi);                                          \
            }                                                                                   \
            if (att) {                                                                          \
                double hs, hcm1;                                                                \
                sin_cosm1(0.5 * th, &hs, &hcm1);                                                \
                double w = 1.0 + hcm1, q0 = b->q[0][l], qi = b->q[1 + I][l],                    \
                       qj = b->q[1 + J][l], qk = b->q[1 + K][l];                                \
                /* q (x) (w, hs e_K): (q0 w - qK hs, qI w + qJ hs, qJ w - qI hs, qK w + q0 hs) */ \
                b->q[0][l] = q0 * w - qk * hs;                                                  \
                b->q[1 + I][l] = qi * w + qj * hs;                                              \
                b->q[1 + J][l] = qj * w - qi * hs;                                              \
                b->q[1 + K][l] = qk * w + q0 * hs;                                              \
            }                                                                                   \
        }                                                                                       \
    }
AXIS_SOA(axis_soa_2, 2, 0, 1)
AXIS_SOA(axis_soa_0, 0, 1, 2)

/* Axis flow a over tau on a block (AX = {2, 0}). */
static inline void axis_soa(Block *b, int a, double tau, int heavy, int att, int n) {
    if (a == 0)
        axis_soa_2(b, tau * COEF[0], heavy, att, n);
    else
        axis_soa_0(b, tau * COEF[1], heavy, att, n);
}

static inline void casimir_soa(Block *b, double tau, int heavy, int att, int n) {
    double t = tau / I[1];
#pragma omp simd
    for (int l = 0; l < n; l++) {
        double v[3] = {t * b->m[0][l], t * b->m[1][l], t * b->m[2][l]};
        double th2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2], p, q;
        if (heavy) {
            pq(th2, &p, &q);
            double A = 1.0 + th2 * p, B = 0.5 - th2 * q;
            double x[3] = {b->g[0][l], b->g[1][l], b->g[2][l]};
            double w[3] = {v[1] * x[2] - v[2] * x[1], v[2] * x[0] - v[0] * x[2], v[0] * x[1] - v[1] * x[0]};
            double u[3] = {v[1] * w[2] - v[2] * w[1], v[2] * w[0] - v[0] * w[2], v[0] * w[1] - v[1] * w[0]};
            for (int c = 0; c < 3; c++) b->g[c][l] = x[c] + (B * u[c] - A * w[c]);
        }
        if (att) {
            double z = 0.25 * th2;
            pq(z, &p, &q);
            double sinc = 1.0 + z * p, c = 1.0 - 0.5 * z + z * z * q;
            double h[3] = {0.5 * sinc * v[0], 0.5 * sinc * v[1], 0.5 * sinc * v[2]};
            double a0 = b->q[0][l], a1 = b->q[1][l], a2 = b->q[2][l], a3 = b->q[3][l];
            b->q[0][l] = a0 * c - a1 * h[0] - a2 * h[1] - a3 * h[2];
            b->q[1][l] = a0 * h[0] + a1 * c + a2 * h[2] - a3 * h[1];
            b->q[2][l] = a0 * h[1] - a1 * h[2] + a2 * c + a3 * h[0];
            b->q[3][l] = a0 * h[2] + a1 * h[1] - a2 * h[0] + a3 * c;
        }
    }
}

static inline void kick_soa(Block *b, double tau, int n) {
    const double *c = CVEC;
#pragma omp simd
    for (int l = 0; l < n; l++) {
        double g0 = b->g[0][l], g1 = b->g[1][l], g2 = b->g[2][l];
        b->m[0][l] += tau * (g1 * c[2] - g2 * c[1]);
        b->m[1][l] += tau * (g2 * c[0] - g0 * c[2]);
        b->m[2][l] += tau * (g0 * c[1] - g1 * c[0]);
    }
}

static void renormalise_soa(Block *b, int n) {
    for (int l = 0; l < n; l++) {
        double q[4] = {b->q[0][l], b->q[1][l], b->q[2][l], b->q[3][l]};
        renormalise(q);
        for (int c = 0; c < 4; c++) b->q[c][l] = q[c];
    }
}

/* `steps` Strang steps of a block of n bodies (the sequence of `run`). */
static void run_soa(Block *b, int n, long steps, double h, int heavy, int att) {
    double h2 = 0.5 * h;
    if (heavy) {
        kick_soa(b, h2, n);
        for (long s = 0; s < steps; s++) {
            axis_soa(b, 0, h2, 1, att, n);
            axis_soa(b, 1, h2, 1, att, n);
            casimir_soa(b, h, 1, att, n);
            axis_soa(b, 1, h2, 1, att, n);
            axis_soa(b, 0, h2, 1, att, n);
            kick_soa(b, s + 1 < steps ? h : h2, n);
            if (att && (s & 255) == 255) renormalise_soa(b, n);
        }
    } else if (att) {
        axis_soa(b, 0, h2, 0, 1, n);
        for (long s = 0; s < steps; s++) {
            axis_soa(b, 1, h2, 0, 1, n);
            casimir_soa(b, h, 0, 1, n);
            axis_soa(b, 1, h2, 0, 1, n);
            axis_soa(b, 0, s + 1 < steps ? h : h2, 0, 1, n);
            if ((s & 255) == 255) renormalise_soa(b, n);
        }
    } else {
        axis_soa(b, 0, h2, 0, 0, n);
        for (long s = 0; s < steps; s++) {
            axis_soa(b, 1, h, 0, 0, n);
            axis_soa(b, 0, s + 1 < steps ? h : h2, 0, 0, n);
        }
    }
}

int main(int argc, char **argv) {
    if (argc != 6) {
        fprintf(stderr, "usage: %s rigid|heavy ATTITUDE BODIES STEPS THREADS\n", argv[0]);
        return 2;
    }
    int heavy = strcmp(argv[1], "heavy") == 0, att = atoi(argv[2]);
    long bodies = atol(argv[3]), steps = atol(argv[4]);
    int threads = atoi(argv[5]);
    for (int a = 0; a < 2; a++) COEF[a] = 1.0 / I[AX[a]] - 1.0 / I[1];
    double nchi = sqrt(CHI[0] * CHI[0] + CHI[1] * CHI[1] + CHI[2] * CHI[2]);
    for (int i = 0; i < 3; i++) CVEC[i] = MGL * CHI[i] / nchi;
    Body *b = malloc(sizeof(Body) * bodies);
    for (long k = 0; k < bodies; k++) {
        /* The same initial states as c_loop.py: body k from the seeded formula below. */
        double x = (double)k;
        b[k].m[0] = 1.0 + 0.1 * sin(1.3 * x);
        b[k].m[1] = 0.5 + 0.1 * sin(2.1 * x + 0.4);
        b[k].m[2] = -0.3 + 0.1 * sin(0.7 * x + 1.1);
        /* Gamma = R^T e3 with R = I (the heavy top's state with or without its attitude). */
        b[k].g[0] = b[k].g[1] = 0.0;
        b[k].g[2] = 1.0;
        b[k].q[0] = 1.0;
        b[k].q[1] = b[k].q[2] = b[k].q[3] = 0.0;
    }
    long blocks = (bodies + BLOCK - 1) / BLOCK;
    Block *soa = malloc(sizeof(Block) * blocks);
    for (long k = 0; k < bodies; k++) {
        Block *bl = &soa[k / BLOCK];
        int l = (int)(k % BLOCK);
        for (int c = 0; c < 3; c++) bl->m[c][l] = b[k].m[c], bl->g[c][l] = b[k].g[c];
        for (int c = 0; c < 4; c++) bl->q[c][l] = b[k].q[c];
    }
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    if (bodies == 1) {
        run(&b[0], steps, 0.01, heavy, att);
    } else {
#ifdef _OPENMP
        omp_set_num_threads(threads);
#pragma omp parallel for schedule(static)
#endif
        for (long k = 0; k < blocks; k++) {
            long n = bodies - k * BLOCK < BLOCK ? bodies - k * BLOCK : BLOCK;
            run_soa(&soa[k], (int)n, steps, 0.01, heavy, att);
        }
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if (bodies > 1) {
        for (int c = 0; c < 3; c++) b[0].m[c] = soa[0].m[c][0], b[0].g[c] = soa[0].g[c][0];
        for (int c = 0; c < 4; c++) b[0].q[c] = soa[0].q[c][0];
    }
    free(soa);
    double sec = (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec);
    double *q = b[0].q;
    double r[9] = {1 - 2 * (q[2] * q[2] + q[3] * q[3]), 2 * (q[1] * q[2] - q[0] * q[3]), 2 * (q[1] * q[3] + q[0] * q[2]),
                   2 * (q[1] * q[2] + q[0] * q[3]), 1 - 2 * (q[1] * q[1] + q[3] * q[3]), 2 * (q[2] * q[3] - q[0] * q[1]),
                   2 * (q[1] * q[3] - q[0] * q[2]), 2 * (q[2] * q[3] + q[0] * q[1]), 1 - 2 * (q[1] * q[1] + q[2] * q[2])};
    printf("%.9f\n", sec);
    printf("%.17g %.17g %.17g %.17g %.17g %.17g\n", b[0].m[0], b[0].m[1], b[0].m[2], b[0].g[0], b[0].g[1], b[0].g[2]);
    for (int i = 0; i < 9; i++) printf("%.17g ", r[i]);
    printf("\n");
    free(b);
    return 0;
}
