/* Baseline for woodpile's speed claims: the paper's standard scene integrated by classical RK4
 * in plain C, the way a careful hand-written code would do it (full chain every step, power 3/2
 * only for compressed contacts). Built with gcc -O3 -march=x86-64-v3 (the instruction set woodpile
 * is built for) by `make bench`; prints one JSON line.
 *
 * Scene: sites -100..100 (201), fixed walls pushing through a Hertz contact, one linear defect
 * eps = 10, kappa = 1 at site 0, impulse u'(-25) = 1, t in [0, 150], dt = 0.01 (argument 1).
 * E_tr: energy density (paper Eq. 5, bonds split half to each neighbour, wall bond to the end
 * site) summed over sites -1..1, over the total. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define S 201
#define N (S + 1) /* sites, then the resonator */
#define DEFECT 100
#define STRIKER 75

static const double EPS = 10.0, KAPPA = 1.0;

static double hertz(double d) { return d > 0.0 ? d * sqrt(d) : 0.0; }

static void accel(const double *q, double *a) {
    memset(a, 0, sizeof(double) * N);
    for (int b = 0; b < S - 1; b++) {
        double d = q[b] - q[b + 1];
        if (d > 0.0) {
            double f = d * sqrt(d);
            a[b] -= f;
            a[b + 1] += f;
        }
    }
    a[0] += hertz(-q[0]);
    a[S - 1] -= hertz(q[S - 1]);
    double f = KAPPA * (q[DEFECT] - q[S]);
    a[DEFECT] -= f;
    a[S] = f / EPS;
}

static double run(double dt, double t_end) {
    static double q[N], v[N], qs[N], vs[N], a1[N], a2[N], a3[N], a4[N], v2[N], v3[N], v4[N];
    memset(q, 0, sizeof q);
    memset(v, 0, sizeof v);
    v[STRIKER] = 1.0;
    long steps = (long)ceil(t_end / dt - 1e-9);
    double h = t_end / steps;
    for (long k = 0; k < steps; k++) {
        accel(q, a1);
        for (int i = 0; i < N; i++) { qs[i] = q[i] + 0.5 * h * v[i]; v2[i] = v[i] + 0.5 * h * a1[i]; }
        accel(qs, a2);
        for (int i = 0; i < N; i++) { qs[i] = q[i] + 0.5 * h * v2[i]; v3[i] = v[i] + 0.5 * h * a2[i]; }
        accel(qs, a3);
        for (int i = 0; i < N; i++) { qs[i] = q[i] + h * v3[i]; v4[i] = v[i] + h * a3[i]; }
        accel(qs, a4);
        for (int i = 0; i < N; i++) {
            q[i] += h / 6.0 * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]);
            v[i] += h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]);
        }
    }
    double e[S], total = 0.0, trapped = 0.0;
    for (int n = 0; n < S; n++) e[n] = 0.5 * v[n] * v[n];
    for (int b = 0; b < S - 1; b++) {
        double d = q[b] - q[b + 1];
        double p = d > 0.0 ? 0.4 * d * d * sqrt(d) : 0.0;
        e[b] += 0.5 * p;
        e[b + 1] += 0.5 * p;
    }
    if (-q[0] > 0.0) e[0] += 0.4 * pow(-q[0], 2.5);
    if (q[S - 1] > 0.0) e[S - 1] += 0.4 * pow(q[S - 1], 2.5);
    double x = q[DEFECT] - q[S];
    e[DEFECT] += 0.5 * EPS * v[S] * v[S] + 0.5 * KAPPA * x * x;
    for (int n = 0; n < S; n++) total += e[n];
    for (int n = DEFECT - 1; n <= DEFECT + 1; n++) trapped += e[n];
    return trapped / total;
}

int main(int argc, char **argv) {
    double dt = argc > 1 ? atof(argv[1]) : 0.01;
    int repeats = argc > 2 ? atoi(argv[2]) : 10;
    double best = 1e30, e_tr = 0.0;
    for (int r = 0; r < repeats; r++) {
        struct timespec t0, t1;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        e_tr = run(dt, 150.0);
        clock_gettime(CLOCK_MONOTONIC, &t1);
        double ms = (t1.tv_sec - t0.tv_sec) * 1e3 + (t1.tv_nsec - t0.tv_nsec) * 1e-6;
        if (ms < best) best = ms;
    }
    printf("{\"implementation\": \"C RK4 (gcc -O3 -march=x86-64-v3)\", \"dt\": %g, \"E_tr\": %.12f, \"ms\": %.3f}\n", dt, e_tr, best);
    return 0;
}
