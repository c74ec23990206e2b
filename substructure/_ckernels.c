/* Compiled kernels of substructure (internal): Timoshenko segments, free-free
 * chains and coupling updates, one loop over frequency lines each.
 *
 * Built by setuptools when the package is installed (a plain C extension: no
 * compiler is needed at run time and nothing is compiled on first use).  The
 * Python side is substructure/_kernels.py, which prepares C-contiguous arrays
 * of fixed dtypes, splits the lines between threads and documents the
 * mathematics; the formulas are those of docs/beams.md.
 *
 * Floating point: IEEE double arithmetic, no reassociation and no contraction
 * into fused multiply-adds (setup flags -fno-fast-math -ffp-contract=off), so
 * that the compensated determinant below is exact and results do not depend
 * on the instruction set.  Complex numbers are pairs of doubles with the
 * textbook product (ac - bd, ad + bc); reciprocals are written out so that a
 * zero divisor gives inf/nan as in numpy instead of trapping.
 *
 * The kernels release the GIL: plain Python threads run them in parallel on
 * disjoint ranges of lines.
 */

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    double re, im;
} cx;

static inline cx mk(double re, double im) { cx z; z.re = re; z.im = im; return z; }
static inline cx cadd(cx a, cx b) { return mk(a.re + b.re, a.im + b.im); }
static inline cx csub(cx a, cx b) { return mk(a.re - b.re, a.im - b.im); }
static inline cx cneg(cx a) { return mk(-a.re, -a.im); }
static inline cx cmul(cx a, cx b) { return mk(a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re); }
static inline cx cscale(double s, cx a) { return mk(s * a.re, s * a.im); }

/* 1 / z by Smith's method; inf/nan for z = 0. */
static inline cx cinv(cx z)
{
    double r, d;
    if (fabs(z.re) >= fabs(z.im)) {
        r = z.im / z.re;
        d = z.re + z.im * r;
        return mk(1.0 / d, -r / d);
    }
    r = z.re / z.im;
    d = z.re * r + z.im;
    return mk(r / d, -1.0 / d);
}

/* 1 / z = conj(z) / |z|^2 for z well inside the range of doubles, else Smith's. */
static inline cx crecip(cx z)
{
    double d = z.re * z.re + z.im * z.im;
    if (d > 1e-290 && d < 1e290) {
        double f = 1.0 / d;
        return mk(z.re * f, -z.im * f);
    }
    return cinv(z);
}

#define SPLIT 134217729.0 /* 2^27 + 1: Veltkamp's splitting */

/* a1 b1 + a2 b2 + a3 b3 + a4 b4 as accurate as in twice the precision (Ogita, Rump and Oishi's Dot2). */
static double dot4(const double a[4], const double b[4])
{
    double total = 0.0, err = 0.0;
    for (int k = 0; k < 4; k++) {
        double x = a[k], y = b[k];
        double p = x * y;
        double t = SPLIT * x;
        double xh = t - (t - x);
        double xl = x - xh;
        t = SPLIT * y;
        double yh = t - (t - y);
        double yl = y - yh;
        err += ((xh * yh - p) + xh * yl + xl * yh) + xl * yl;
        double s = total + p;
        double z = s - total;
        err += (total - (s - z)) + (p - z);
        total = s;
    }
    return total + err;
}

/* a d - b c, compensated where the two products cancel to less than 1e-3 of their size. */
static inline cx det2(cx a, cx b, cx c, cx d)
{
    cx ad = cmul(a, d), bc = cmul(b, c);
    cx det = csub(ad, bc);
    double size = fabs(ad.re) + fabs(ad.im) + fabs(bc.re) + fabs(bc.im);
    if (fabs(det.re) + fabs(det.im) > 1e-3 * size)
        return det;
    double x1[4] = {a.re, -a.im, -b.re, b.im}, y1[4] = {d.re, d.im, c.re, c.im};
    double x2[4] = {a.re, a.im, -b.re, -b.im}, y2[4] = {d.im, d.re, c.im, c.re};
    return mk(dot4(x1, y1), dot4(x2, y2));
}

/* Principal square root (Re >= 0, branch cut on the negative real axis, as numpy). */
static inline cx csqrt_(cx z)
{
    double x = z.re, y = z.im;
    if (x == 0.0 && y == 0.0)
        return mk(0.0, y);
    double r2 = x * x + y * y;
    double r = (r2 > 0.0 && r2 < INFINITY) ? sqrt(r2) : hypot(x, y);
    if (x >= 0.0) {
        double t = sqrt(0.5 * (r + x));
        return mk(t, 0.5 * y / t);
    }
    double t = sqrt(0.5 * (r - x));
    return mk(0.5 * fabs(y) / t, copysign(t, y));
}

/* ------------------------------------------------------------------------ */
/* Lanes: four frequency lines at once
 *
 * The closed form and the chain run on blocks of VL = 4 lines of one
 * configuration.  Each quantity is a vector over the lanes (GCC and Clang
 * vector extensions): the compiler keeps it in registers and emits vector
 * instructions (AVX2 where the processor has it, else SSE2 pairs; see
 * KERNEL_CLONES).  Each lane computes exactly what a line on its own would:
 * the same operations in the same order, branches as per-lane selections,
 * and the rare special cases (a zero or huge argument of a square root, a
 * determinant that cancels) redone lane by lane with the scalar functions
 * above.  So a line's result does not depend on the lines it shares a block
 * with, nor on how the lines are split between threads, nor on the
 * instruction set.  The exponentials, cosines and sines are the C library's,
 * called lane by lane in a loop of their own over all the segments of a block
 * (see waves, transcendentals and transfer below). */

#ifndef VL
#define VL 4
#endif
#define AI static inline __attribute__((always_inline))

typedef double vd __attribute__((vector_size(8 * VL)));
typedef long long vm __attribute__((vector_size(8 * VL))); /* lane masks: all bits set or clear */
typedef struct {
    vd re, im;
} cv;

AI vd splat(double x)
{
    vd v;
    for (int l = 0; l < VL; l++)
        v[l] = x;
    return v;
}
AI vm msplat(long long x)
{
    vm v;
    for (int l = 0; l < VL; l++)
        v[l] = x;
    return v;
}
AI vd vsel(vm mask, vd a, vd b) { return (vd)(((vm)a & mask) | ((vm)b & ~mask)); }
AI vd vabs(vd x)
{
    return (vd)((vm)x & msplat(INT64_MAX));
}
/* |mag| with the sign of sgn */
AI vd vcopysign(vd mag, vd sgn)
{
    return (vd)(((vm)vabs(mag)) | ((vm)sgn & msplat(INT64_MIN)));
}
AI vd vsqrt(vd x)
{
    vd r;
    for (int l = 0; l < VL; l++)
        r[l] = sqrt(x[l]);
    return r;
}
AI vd vmax(vd a, vd b) { return vsel(a > b, a, b); }
AI int any(vm m)
{
    long long r = 0;
    for (int l = 0; l < VL; l++)
        r |= m[l];
    return r != 0;
}
AI int all(vm m)
{
    long long r = -1;
    for (int l = 0; l < VL; l++)
        r &= m[l];
    return r != 0;
}

AI cv V(vd re, vd im) { cv z; z.re = re; z.im = im; return z; }
AI cv vc(cx z) { return V(splat(z.re), splat(z.im)); }
AI cx lane(cv a, int l) { return mk(a.re[l], a.im[l]); }
AI cv vadd(cv a, cv b) { return V(a.re + b.re, a.im + b.im); }
AI cv vsub(cv a, cv b) { return V(a.re - b.re, a.im - b.im); }
AI cv vneg(cv a) { return V(-a.re, -a.im); }
AI cv vmul(cv a, cv b) { return V(a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re); }
AI cv vmulc(cv a, cx b) { return V(a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re); }
AI cv vscale(vd s, cv a) { return V(s * a.re, s * a.im); }
/* a0 b0 + a1 b1 */
AI cv vdot2(cv a0, cv b0, cv a1, cv b1) { return vadd(vmul(a0, b0), vmul(a1, b1)); }
/* ((a0 b0 + a1 b1) + a2 b2) + a3 b3 */
AI cv vdot4(cv a0, cv b0, cv a1, cv b1, cv a2, cv b2, cv a3, cv b3)
{
    return vadd(vadd(vadd(vmul(a0, b0), vmul(a1, b1)), vmul(a2, b2)), vmul(a3, b3));
}

/* Principal square root per lane, as csqrt_. */
AI cv vcsqrt(cv z)
{
    vd x = z.re, y = z.im;
    vd r2 = x * x + y * y;
    vd t = vsqrt(splat(0.5) * (vsqrt(r2) + vabs(x)));
    vd w = splat(0.5) * y / t;
    vm pos = x >= splat(0.0);
    cv r = V(vsel(pos, t, vabs(w)), vsel(pos, w, vcopysign(t, y)));
    vm special = ~((r2 > splat(0.0)) & (r2 < splat(INFINITY)));
    if (any(special))
        for (int l = 0; l < VL; l++)
            if (special[l]) {
                cx s = csqrt_(lane(z, l));
                r.re[l] = s.re;
                r.im[l] = s.im;
            }
    return r;
}

/* 1 / z per lane, as crecip. */
AI cv vrecip(cv z)
{
    vd d = z.re * z.re + z.im * z.im;
    vd f = splat(1.0) / d;
    cv r = V(z.re * f, -z.im * f);
    vm special = ~((d > splat(1e-290)) & (d < splat(1e290)));
    if (any(special))
        for (int l = 0; l < VL; l++)
            if (special[l]) {
                cx s = cinv(lane(z, l));
                r.re[l] = s.re;
                r.im[l] = s.im;
            }
    return r;
}

/* 1 / z per lane by Smith's method, as cinv. */
AI cv vinv(cv z)
{
    vm big = vabs(z.re) >= vabs(z.im);
    vd p = vsel(big, z.im, z.re), q = vsel(big, z.re, z.im);
    vd s = p / q;
    vd d = q + p * s;
    vd one = splat(1.0);
    return V(vsel(big, one, s) / d, -vsel(big, s, one) / d);
}

/* a d - b c per lane, as det2. */
AI cv vdet2(cv a, cv b, cv c, cv d)
{
    cv ad = vmul(a, d), bc = vmul(b, c);
    cv det = vsub(ad, bc);
    vd size = vabs(ad.re) + vabs(ad.im) + vabs(bc.re) + vabs(bc.im);
    vm special = ~((vabs(det.re) + vabs(det.im)) > splat(1e-3) * size);
    if (any(special))
        for (int l = 0; l < VL; l++)
            if (special[l]) {
                cx s = det2(lane(a, l), lane(b, l), lane(c, l), lane(d, l));
                det.re[l] = s.re;
                det.im[l] = s.im;
            }
    return det;
}

/* ------------------------------------------------------------------------ */
/* Segments */

#define SERIES_LIMIT2 0.25 /* |s L^2| < 0.5, squared (docs/beams.md) */
static double inv_factorial[24];
static double series_bound2[12]; /* |z|^2 up to which n terms suffice: |z|^n / (2n)! <= 1e-18 */

/* Per-segment constants: a / w2, e / w2, rhoA / EI, 1 / EI, 1 / kGA. */
static void coefficients(cx ei, cx kga, double rhoa, double rhoi, cx out[5])
{
    cx iei = cinv(ei), ikga = cinv(kga);
    out[0] = cscale(-rhoa, ikga);
    out[1] = cscale(-rhoi, iei);
    out[2] = cscale(rhoa, iei);
    out[3] = iei;
    out[4] = ikga;
}

/* a, e (the diagonal of A^2) and the eigenvalues s1, s2 of A^2 at w2 = omega^2, one line. */
static inline void wavenumbers(const cx co[5], double w2, cx *a, cx *e, cx *s1, cx *s2)
{
    *a = cscale(w2, co[0]);
    *e = cscale(w2, co[1]);
    cx half = cscale(0.5, csub(*a, *e));
    cx root = csqrt_(cadd(cmul(half, half), cscale(w2, co[2])));
    cx mean = cscale(0.5, cadd(*a, *e));
    *s1 = cadd(mean, root);
    *s2 = csub(mean, root);
}

/* The transfer matrix of a segment, T = exp(A L), on the lanes, in three phases.
 *
 * exp(A L) = C(A^2) + A S(A^2), C(s) = cosh(L sqrt s), S(s) = sinh(L sqrt s) / sqrt s, and
 * g(A^2) = g(s2) I + g[s1, s2] (A^2 - s2 I).  The divided differences come from their power
 * series where max |s L^2| < 0.5 (terms until |z|^n / (2n)! < 1e-18, counted per lane), else
 * from one exponential per wavenumber.  T = alpha I + beta A + gamma A^2 + delta A^3.
 *
 * The phases run over all the segments of a block of lines in turn: the wavenumbers of every
 * segment (waves), then the exponentials, cosines and sines of every segment (transcendentals:
 * a plain loop of library calls, no vector value lives across a call), then the rest
 * (transfer).  Each phase's work on one segment is independent of the other segments', so
 * the processor overlaps the long chains of square roots and divisions of one segment with
 * those of the next instead of waiting for each in turn between the calls. */

typedef struct {
    cv a, e, s1, s2, r1, r2; /* a, e: diagonal of A^2; s1, s2 its eigenvalues; r = sqrt(s) */
    vd bound2;               /* max |s L^2|^2 */
    vm series;               /* lanes on the power series */
    int some_series, some_exp;
    double x[2][VL], y[2][VL];      /* r L = x + i y of both wavenumbers, exponential lanes */
    double p[2][VL], c[2][VL], s[2][VL]; /* exp(x), cos(y), sin(y) */
} wave_t;

/* Phase 1: wavenumbers, the choice series/exponential per lane, and r L where needed (w2 = omega^2 per lane,
 * complex where omega is: the model at a complex frequency, as seen through an exponential window). */
AI void waves(const cx co[5], double length, cv w2, const int cplx, wave_t *wv)
{
    /* cplx: a constant where inlined (chain_range's two versions): real lines keep the real products */
    cv a = cplx ? vmulc(w2, co[0]) : vscale(w2.re, vc(co[0])), e = cplx ? vmulc(w2, co[1]) : vscale(w2.re, vc(co[1]));
    cv half = vscale(splat(0.5), vsub(a, e));
    cv root = vcsqrt(vadd(vmul(half, half), cplx ? vmulc(w2, co[2]) : vscale(w2.re, vc(co[2]))));
    cv mean = vscale(splat(0.5), vadd(a, e));
    cv s1 = vadd(mean, root), s2 = vsub(mean, root);
    double l2 = length * length;
    cv z1 = vscale(splat(l2), s1), z2 = vscale(splat(l2), s2);
    vd bound2 = vmax(z1.re * z1.re + z1.im * z1.im, z2.re * z2.re + z2.im * z2.im);
    vm series = bound2 < splat(SERIES_LIMIT2);
    wv->a = a;
    wv->e = e;
    wv->s1 = s1;
    wv->s2 = s2;
    wv->bound2 = bound2;
    wv->series = series;
    wv->some_series = any(series);
    wv->some_exp = !all(series);
    if (wv->some_exp) {
        cv r1 = vcsqrt(s1), r2 = vcsqrt(s2);
        wv->r1 = r1;
        wv->r2 = r2;
        vd x1 = r1.re * length, y1 = r1.im * length, x2 = r2.re * length, y2 = r2.im * length;
        for (int l = 0; l < VL; l++) {
            wv->x[0][l] = x1[l];
            wv->y[0][l] = y1[l];
            wv->x[1][l] = x2[l];
            wv->y[1][l] = y2[l];
        }
    }
}

/* Phase 2: exp(x), cos(y), sin(y) of both wavenumbers on the exponential lanes of n segments. */
static inline void transcendentals(wave_t *wv, Py_ssize_t n)
{
    for (Py_ssize_t u = 0; u < n; u++) {
        wave_t *w = wv + u;
        if (!w->some_exp)
            continue;
        for (int l = 0; l < VL; l++)
            for (int k = 0; k < 2; k++) {
                if (w->series[l]) { /* a series lane: not used */
                    w->p[k][l] = w->c[k][l] = 1.0;
                    w->s[k][l] = 0.0;
                    continue;
                }
                w->p[k][l] = exp(w->x[k][l]);
                w->c[k][l] = cos(w->y[k][l]);
                w->s[k][l] = sin(w->y[k][l]);
            }
    }
}

AI vd vload(const double *x)
{
    vd v;
    memcpy(&v, x, sizeof v);
    return v;
}

/* Phase 3: the 16 entries (row-major) of T on the lanes, w2 = omega^2 per lane. */
AI void transfer(const cx co[5], double rhoa, double rhoi, double length, cv w2, const int cplx, const wave_t *wv,
                 cv *t)
{
    cv a = wv->a, e = wv->e, s1 = wv->s1, s2 = wv->s2;
    vm series = wv->series;
    double l2 = length * length;
    cv c0, c1, g0, g1;
    if (wv->some_series) {
        cv z1 = vscale(splat(l2), s1), z2 = vscale(splat(l2), s2);
        vd bound2 = wv->bound2;
        /* h_n: complete homogeneous symmetric polynomial of degree n in z1, z2; pow2 = z2^n;
         * lane l takes the terms n <= nt[l] */
        vm nt = msplat(0);
        long long nt_min = 99, nt_max = 0;
        for (int l = 0; l < VL; l++)
            if (series[l]) {
                long long n = 2;
                while (bound2[l] > series_bound2[n])
                    n++;
                nt[l] = n;
                nt_max = n > nt_max ? n : nt_max;
                nt_min = n < nt_min ? n : nt_min;
            }
        cv one = V(splat(1.0), splat(0.0)), zero = V(splat(0.0), splat(0.0));
        cv sc = one, ss = one, dc = zero, ds = zero, h = one, pow2 = one;
        /* the terms every series lane takes (exponential lanes are replaced below) */
        for (long long n = 1; n <= nt_min; n++) {
            vd rc = splat(inv_factorial[2 * n]), rs = splat(inv_factorial[2 * n + 1]);
            dc = vadd(dc, vscale(rc, h));
            ds = vadd(ds, vscale(rs, h));
            pow2 = vmul(pow2, z2);
            sc = vadd(sc, vscale(rc, pow2));
            ss = vadd(ss, vscale(rs, pow2));
            h = vadd(vmul(z1, h), pow2);
        }
        /* the terms only some lanes take */
        for (long long n = nt_min + 1; n <= nt_max; n++) {
            vd rc = splat(inv_factorial[2 * n]), rs = splat(inv_factorial[2 * n + 1]);
            vm on = nt >= msplat(n);
            cv ndc = vadd(dc, vscale(rc, h)), nds = vadd(ds, vscale(rs, h));
            pow2 = vmul(pow2, z2);
            cv nsc = vadd(sc, vscale(rc, pow2)), nss = vadd(ss, vscale(rs, pow2));
            h = vadd(vmul(z1, h), pow2);
            dc = V(vsel(on, ndc.re, dc.re), vsel(on, ndc.im, dc.im));
            ds = V(vsel(on, nds.re, ds.re), vsel(on, nds.im, ds.im));
            sc = V(vsel(on, nsc.re, sc.re), vsel(on, nsc.im, sc.im));
            ss = V(vsel(on, nss.re, ss.re), vsel(on, nss.im, ss.im));
        }
        c0 = sc;
        c1 = vscale(splat(l2), dc);
        g0 = vscale(splat(length), ss);
        g1 = vscale(splat(l2 * length), ds);
    }
    if (wv->some_exp) {
        /* cosh and sinh from exp(r L) = e^x (cos y + i sin y); Re r >= 0 */
        cv r1 = wv->r1, r2 = wv->r2;
        vd p1 = vload(wv->p[0]), p2 = vload(wv->p[1]);
        vd cy1 = vload(wv->c[0]), sy1 = vload(wv->s[0]), cy2 = vload(wv->c[1]), sy2 = vload(wv->s[1]);
        vd half1 = splat(0.5);
        vd q1 = splat(1.0) / p1, q2 = splat(1.0) / p2;
        cv ch1 = V(half1 * (p1 + q1) * cy1, half1 * (p1 - q1) * sy1);
        cv ch2 = V(half1 * (p2 + q2) * cy2, half1 * (p2 - q2) * sy2);
        cv sh1 = vmul(V(half1 * (p1 - q1) * cy1, half1 * (p1 + q1) * sy1), vrecip(r1));
        cv sh2 = vmul(V(half1 * (p2 - q2) * cy2, half1 * (p2 + q2) * sy2), vrecip(r2));
        cv ids = vrecip(vsub(s1, s2));
        cv ec1 = vmul(vsub(ch1, ch2), ids), eg1 = vmul(vsub(sh1, sh2), ids);
        if (!wv->some_series) {
            c0 = ch2; c1 = ec1; g0 = sh2; g1 = eg1;
        } else {
            c0 = V(vsel(series, c0.re, ch2.re), vsel(series, c0.im, ch2.im));
            c1 = V(vsel(series, c1.re, ec1.re), vsel(series, c1.im, ec1.im));
            g0 = V(vsel(series, g0.re, sh2.re), vsel(series, g0.im, sh2.im));
            g1 = V(vsel(series, g1.re, eg1.re), vsel(series, g1.im, eg1.im));
        }
    }
    cv alpha = vsub(c0, vmul(c1, s2)), beta = vsub(g0, vmul(g1, s2));
    cv gamma = c1, delta = g1;
    cx iei = co[3], ikga = co[4];
    /* omega^2 rho A and omega^2 rho I: real on real lines (their products with a complex number real-scaled) */
    cv ma = vscale(splat(rhoa), w2), mi = vscale(splat(rhoi), w2);
#define MSCALE(m, z) (cplx ? vmul((m), (z)) : vscale((m).re, (z)))
    cv d00 = vadd(alpha, vmul(gamma, a)), d11 = vadd(alpha, vmul(gamma, e));
    t[0] = d00;
    t[10] = d00;
    t[5] = d11;
    t[15] = d11;
    t[1] = vadd(beta, vmul(delta, vadd(a, e)));
    cv u = vmulc(a, ikga);
    u = V(u.re - iei.re, u.im - iei.im);
    t[2] = vadd(vmulc(beta, ikga), vmul(delta, u));
    t[3] = vmulc(gamma, iei);
    t[6] = vneg(t[3]);
    t[4] = vmulc(MSCALE(ma, delta), iei);
    t[11] = vneg(t[4]);
    t[7] = vmulc(vadd(beta, vmul(delta, e)), iei);
    t[8] = vneg(MSCALE(ma, vadd(beta, vmul(delta, a))));
    t[12] = MSCALE(ma, gamma);
    t[9] = vneg(t[12]);
    /* t31 = -mi beta + delta (ma - mi e), t32 = -beta + delta (mi / EI - a) */
    t[13] = vadd(MSCALE(vneg(mi), beta), vmul(delta, vsub(ma, MSCALE(mi, e))));
    t[14] = vadd(vneg(beta), vmul(delta, vsub(MSCALE(mi, vc(iei)), a)));
#undef MSCALE
}

/* ------------------------------------------------------------------------ */
/* Chains */

/* The VL lanes of z to o[0 .. VL - 1] (complex numbers: re, im interleaved). */
AI void store_lanes(cx *o, cv z)
{
#if VL == 4 && (defined(__clang__) || (defined(__GNUC__) && __GNUC__ >= 5))
    /* two interleaving shuffles and two full-width stores instead of eight scalar ones */
#if defined(__clang__)
    vd lo = __builtin_shufflevector(z.re, z.im, 0, 4, 1, 5), hi = __builtin_shufflevector(z.re, z.im, 2, 6, 3, 7);
#else
    vd lo = __builtin_shuffle(z.re, z.im, (vm){0, 4, 1, 5}), hi = __builtin_shuffle(z.re, z.im, (vm){2, 6, 3, 7});
#endif
    memcpy(o, &lo, sizeof lo);
    memcpy(o + 2, &hi, sizeof hi);
#else
    for (int l = 0; l < VL; l++)
        o[l] = lane(z, l);
#endif
}

/* y = t x: t 4x4, x and y 4x2 (row-major; x's rows xs apart, a constant where inlined) */
AI void times_columns(const cv *t, const cv *x, int xs, cv *y)
{
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 2; c++)
            y[2 * r + c] = vdot4(t[4 * r], x[c], t[4 * r + 1], x[xs + c], t[4 * r + 2], x[2 * xs + c], t[4 * r + 3],
                                 x[3 * xs + c]);
}

/* columns c0 .. 3 of y = x t: x and y 2x4, t 4x4 (row-major); c0 a constant where inlined */
AI void rows_times(const cv *x, const cv *t, cv *y, int c0)
{
    for (int r = 0; r < 2; r++)
        for (int c = c0; c < 4; c++)
            y[4 * r + c] = vdot4(x[4 * r], t[c], x[4 * r + 1], t[4 + c], x[4 * r + 2], t[8 + c], x[4 * r + 3], t[12 + c]);
}

/* Free-free receptances of a chain at its nodes on the lanes: lines q .. q + nb - 1 of out.
 *
 * Y_ij = P_i,uu M_Fu^-1 S_j,FF for x_i <= x_j, with P_i = T(0 -> x_i), S_j = T(x_j -> L),
 * M = T(0 -> L) (state [u; F]); Y_ji = Y_ij^T (reciprocity: no cancelling second term).
 * tmat: the 16 entries of each distinct segment's T.  Only the u-columns of T(0 -> x) (from
 * the base) and the F-rows of T(x -> L) (from the tip) are multiplied. */
AI void chain_block(const cv *tmat, const int64_t *seg_of, Py_ssize_t n_int, const int64_t *nodes,
                    const int64_t *place, Py_ssize_t m, cx *out, Py_ssize_t n_lines, Py_ssize_t q, int nb, cv *pre,
                    cv *post)
{
    const cv one = V(splat(1.0), splat(0.0)), zero = V(splat(0.0), splat(0.0));
    /* the products live in memory (two buffers each, used in turn): few values in registers at once.
     * The first segment's matrix is read where it is (no copy): cs is the stride between rows. */
    cv buf[32];
    const cv *cols = buf; /* u-columns of T(0 -> x), 4x2: entry (r, c) at cols[cs * r + c] */
    int cs = 2;
    {
        Py_ssize_t p = 0;
        int fresh = 1;
        for (Py_ssize_t k = 0; k <= n_int; k++) {
            if (p < m && nodes[p] == k) {
                cv *d = pre + 4 * p;
                if (fresh) {
                    d[0] = one; d[1] = zero; d[2] = zero; d[3] = one;
                } else {
                    d[0] = cols[0]; d[1] = cols[1]; d[2] = cols[cs]; d[3] = cols[cs + 1];
                }
                p++;
            }
            if (k == n_int)
                break;
            const cv *t = tmat + 16 * seg_of[k];
            if (fresh) {
                cols = t;
                cs = 4;
                fresh = 0;
            } else {
                cv *next = cols == buf ? buf + 8 : buf;
                if (cs == 4)
                    times_columns(t, cols, 4, next);
                else
                    times_columns(t, cols, 2, next);
                cols = next;
                cs = 2;
            }
        }
    }
    {
        const cv *rows = buf + 16; /* F-rows of T(x -> L), 2x4 row-major */
        Py_ssize_t p = m - 1;
        int fresh = 1;
        for (Py_ssize_t k = n_int; k >= 0; k--) {
            if (p >= 0 && nodes[p] == k) {
                cv *d = post + 4 * p;
                if (fresh) {
                    d[0] = one; d[1] = zero; d[2] = zero; d[3] = one;
                } else {
                    d[0] = rows[2]; d[1] = rows[3]; d[2] = rows[6]; d[3] = rows[7];
                }
                p--;
            }
            if (k == 0 || p < 0)
                break;
            const cv *t = tmat + 16 * seg_of[k - 1];
            if (fresh) {
                rows = t + 8;
                fresh = 0;
            } else {
                cv *next = rows == buf + 16 ? buf + 24 : buf + 16;
                /* the last product (reaching the first node) needs only the F-columns */
                if (p == 0 && nodes[0] == k - 1)
                    rows_times(rows, t, next, 2);
                else
                    rows_times(rows, t, next, 0);
                rows = next;
            }
        }
    }
    const cv c4 = cols[2 * cs], c5 = cols[2 * cs + 1], c6 = cols[3 * cs], c7 = cols[3 * cs + 1];
    /* M_Fu^-1, M_Fu = [[c4, c5], [c6, c7]] */
    cv idet = vinv(vdet2(c4, c5, c6, c7));
    cv i00 = vmul(c7, idet), i11 = vmul(c4, idet), i01 = vmul(vneg(c5), idet), i10 = vmul(vneg(c6), idet);
    Py_ssize_t w = 2 * m; /* out is (w, w, n_lines) */
    for (Py_ssize_t i = 0; i < m; i++) {
        /* left = P_i,uu M_Fu^-1; P = I at the base (a product with I would change only signs of zeros) */
        cv l00 = i00, l01 = i01, l10 = i10, l11 = i11;
        if (nodes[i] != 0) {
            const cv *pi_ = pre + 4 * i;
            l00 = vdot2(pi_[0], i00, pi_[1], i10);
            l01 = vdot2(pi_[0], i01, pi_[1], i11);
            l10 = vdot2(pi_[2], i00, pi_[3], i10);
            l11 = vdot2(pi_[2], i01, pi_[3], i11);
        }
        Py_ssize_t a = 2 * place[i];
        for (Py_ssize_t j = i; j < m; j++) {
            Py_ssize_t b = 2 * place[j];
            cv y[4] = {l00, l01, l10, l11}; /* S_j,FF = I at the tip */
            if (nodes[j] != n_int) {
                const cv *s = post + 4 * j;
                y[0] = vdot2(l00, s[0], l01, s[2]);
                y[1] = vdot2(l00, s[1], l01, s[3]);
                y[2] = vdot2(l10, s[0], l11, s[2]);
                y[3] = vdot2(l10, s[1], l11, s[3]);
            }
            cx *o = out + (a * w + b) * n_lines + q;
            if (nb == VL) {
                store_lanes(o, y[0]);
                store_lanes(o + n_lines, y[1]);
                store_lanes(o + w * n_lines, y[2]);
                store_lanes(o + (w + 1) * n_lines, y[3]);
                if (j > i) { /* Y_ji = Y_ij^T */
                    o = out + (b * w + a) * n_lines + q;
                    store_lanes(o, y[0]);
                    store_lanes(o + n_lines, y[2]);
                    store_lanes(o + w * n_lines, y[1]);
                    store_lanes(o + (w + 1) * n_lines, y[3]);
                }
            } else {
                Py_ssize_t at[4] = {(a * w + b) * n_lines, (a * w + b + 1) * n_lines, ((a + 1) * w + b) * n_lines,
                                    ((a + 1) * w + b + 1) * n_lines};
                Py_ssize_t tr[4] = {(b * w + a) * n_lines, ((b + 1) * w + a) * n_lines, (b * w + a + 1) * n_lines,
                                    ((b + 1) * w + a + 1) * n_lines};
                for (int k = 0; k < 4; k++)
                    for (int side = 0; side < (j > i ? 2 : 1); side++) {
                        cx *d = out + (side ? tr[k] : at[k]) + q;
                        for (int l = 0; l < nb; l++)
                            d[l] = lane(y[k], l);
                    }
            }
        }
    }
}

#if defined(__x86_64__) && defined(__GNUC__) && defined(__ELF__) && !defined(SUBSTRUCTURE_NO_CLONES)
/* One version of the line loop per instruction set, chosen when the module loads. */
#define KERNEL_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define KERNEL_CLONES
#endif

/* The line loop of chain_real and chain_complex, cplx a constant where inlined. */
AI void chain_body(const void *omega, Py_ssize_t n_f, const cx *coef, const double *rhoa, const double *rhoi,
                   const double *length, Py_ssize_t n_u, Py_ssize_t n_c, const int64_t *slot, cx *table,
                   const int64_t *seg_of, Py_ssize_t n_int, const int64_t *nodes, const int64_t *place, Py_ssize_t m,
                   cx *out, int table_only, Py_ssize_t lo, Py_ssize_t hi, cv *tmat, cv *pre, cv *post, wave_t *wv,
                   const int cplx)
{
    Py_ssize_t n_lines = table_only ? n_f : n_c * n_f;
    for (Py_ssize_t q = lo; q < hi;) {
        Py_ssize_t c = table_only ? 0 : q / n_f;
        Py_ssize_t i = q - c * n_f;
        Py_ssize_t left = hi - q < n_f - i ? hi - q : n_f - i;
        int nb = left < VL ? (int)left : VL; /* lines of this block, all of configuration c */
        cv w2;
        for (int l = 0; l < VL; l++) {
            Py_ssize_t at = i + (l < nb ? l : nb - 1);
            if (cplx) {
                cx w = ((const cx *)omega)[at];
                w2.re[l] = w.re * w.re - w.im * w.im;
                w2.im[l] = 2.0 * w.re * w.im;
            } else {
                double w = ((const double *)omega)[at];
                w2.re[l] = w * w;
                w2.im[l] = 0.0;
            }
        }
        /* the segments computed here (not read from the table): phases 1 to 3 of the closed form */
        for (Py_ssize_t u = 0; u < n_u; u++) {
            int shared = slot[u] >= 0;
            if (shared ? table_only : !table_only) {
                Py_ssize_t k = u * n_c + c;
                waves(coef + 5 * k, length[k], w2, cplx, wv + u);
            } else
                wv[u].some_exp = 0;
        }
        transcendentals(wv, n_u);
        for (Py_ssize_t u = 0; u < n_u; u++) {
            int shared = slot[u] >= 0;
            cv *t = tmat + 16 * u;
            if (shared && !table_only) {
                for (int k = 0; k < 16; k++) {
                    const cx *src = table + (slot[u] * 16 + k) * n_f + i;
                    for (int l = 0; l < VL; l++) {
                        cx z = src[l < nb ? l : nb - 1];
                        t[k].re[l] = z.re;
                        t[k].im[l] = z.im;
                    }
                }
            } else if (shared || !table_only) {
                Py_ssize_t k = u * n_c + c;
                transfer(coef + 5 * k, rhoa[k], rhoi[k], length[k], w2, cplx, wv + u, t);
                if (table_only)
                    for (int e = 0; e < 16; e++) {
                        cx *dst = table + (slot[u] * 16 + e) * n_f + i;
                        for (int l = 0; l < nb; l++) {
                            dst[l].re = t[e].re[l];
                            dst[l].im = t[e].im[l];
                        }
                    }
            }
        }
        if (!table_only)
            chain_block(tmat, seg_of, n_int, nodes, place, m, out, n_lines, q, nb, pre, post);
        q += nb;
    }
}

/* Lines lo .. hi - 1 (see py_chain_lines) on real lines: the products of omega^2 real, as they always were. */
KERNEL_CLONES static void chain_real(const void *omega, Py_ssize_t n_f, const cx *coef, const double *rhoa,
                                     const double *rhoi, const double *length, Py_ssize_t n_u, Py_ssize_t n_c,
                                     const int64_t *slot, cx *table, const int64_t *seg_of, Py_ssize_t n_int,
                                     const int64_t *nodes, const int64_t *place, Py_ssize_t m, cx *out,
                                     int table_only, Py_ssize_t lo, Py_ssize_t hi, cv *tmat, cv *pre, cv *post,
                                     wave_t *wv)
{
    chain_body(omega, n_f, coef, rhoa, rhoi, length, n_u, n_c, slot, table, seg_of, n_int, nodes, place, m, out,
               table_only, lo, hi, tmat, pre, post, wv, 0);
}

/* The same on complex lines (the model seen through an exponential window). */
__attribute__((noinline)) static void chain_complex(const void *omega, Py_ssize_t n_f, const cx *coef,
                                                    const double *rhoa, const double *rhoi, const double *length,
                                                    Py_ssize_t n_u, Py_ssize_t n_c, const int64_t *slot, cx *table,
                                                    const int64_t *seg_of, Py_ssize_t n_int, const int64_t *nodes,
                                                    const int64_t *place, Py_ssize_t m, cx *out, int table_only,
                                                    Py_ssize_t lo, Py_ssize_t hi, cv *tmat, cv *pre, cv *post,
                                                    wave_t *wv)
{
    chain_body(omega, n_f, coef, rhoa, rhoi, length, n_u, n_c, slot, table, seg_of, n_int, nodes, place, m, out,
               table_only, lo, hi, tmat, pre, post, wv, 1);
}

/* ------------------------------------------------------------------------ */
/* Buffers */

/* Scratch memory aligned for the lane vectors. */
static void *aligned_alloc_(size_t size)
{
    void *p = NULL;
    if (posix_memalign(&p, 64, size ? size : 64) != 0)
        return NULL;
    return p;
}
static void aligned_free_(void *p) { free(p); }

typedef struct {
    Py_buffer view;
    int held;
} buf_t;

static void release(buf_t *b, int n)
{
    for (int i = 0; i < n; i++)
        if (b[i].held) {
            PyBuffer_Release(&b[i].view);
            b[i].held = 0;
        }
}

/* A C-contiguous buffer of ``kind`` ('d' float64, 'Z' complex128, 'q' int64) with ``ndim`` dimensions. */
static int get(PyObject *obj, buf_t *b, char kind, int ndim, int writable, const char *name)
{
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, &b->view, flags) < 0) {
        PyErr_Format(PyExc_TypeError, "%s: expected a C-contiguous%s array", name, writable ? ", writeable" : "");
        return -1;
    }
    b->held = 1;
    const char *f = b->view.format ? b->view.format : "B";
    if (*f == '<' || *f == '=' || *f == '@')
        f++;
    int ok;
    if (kind == 'd')
        ok = strcmp(f, "d") == 0;
    else if (kind == 'Z')
        ok = strcmp(f, "Zd") == 0;
    else
        ok = (strcmp(f, "q") == 0 || strcmp(f, "l") == 0) && b->view.itemsize == 8;
    if (!ok || b->view.ndim != ndim) {
        PyErr_Format(PyExc_TypeError, "%s: expected a %d-dimensional %s array, got format %s with %d dimensions",
                     name, ndim, kind == 'd' ? "float64" : kind == 'Z' ? "complex128" : "int64", f,
                     (int)b->view.ndim);
        return -1;
    }
    return 0;
}

#define SHAPE(b, k) ((b).view.shape[k])

/* ------------------------------------------------------------------------ */
/* segment_coefficients(ei, kga, rhoa, rhoi, omega_max, coef, k_max) */

static PyObject *py_segment_coefficients(PyObject *self, PyObject *args)
{
    PyObject *o[7];
    double omega_max;
    if (!PyArg_ParseTuple(args, "OOOOdOO", &o[0], &o[1], &o[2], &o[3], &omega_max, &o[5], &o[6]))
        return NULL;
    buf_t b[6] = {{0}};
    if (get(o[0], &b[0], 'Z', 2, 0, "ei") || get(o[1], &b[1], 'Z', 2, 0, "kga") ||
        get(o[2], &b[2], 'd', 2, 0, "rhoa") || get(o[3], &b[3], 'd', 2, 0, "rhoi") ||
        get(o[5], &b[4], 'Z', 3, 1, "coef") || get(o[6], &b[5], 'd', 2, 1, "k_max")) {
        release(b, 6);
        return NULL;
    }
    Py_ssize_t n_u = SHAPE(b[0], 0), n_c = SHAPE(b[0], 1);
    for (int k = 1; k < 4; k++)
        if (SHAPE(b[k], 0) != n_u || SHAPE(b[k], 1) != n_c)
            goto shape;
    if (SHAPE(b[4], 0) != n_u || SHAPE(b[4], 1) != n_c || SHAPE(b[4], 2) != 5 || SHAPE(b[5], 0) != n_u ||
        SHAPE(b[5], 1) != n_c)
        goto shape;
    {
        const cx *ei = b[0].view.buf, *kga = b[1].view.buf;
        const double *rhoa = b[2].view.buf, *rhoi = b[3].view.buf;
        cx *coef = b[4].view.buf;
        double *k_max = b[5].view.buf;
        double w2 = omega_max * omega_max;
        for (Py_ssize_t k = 0; k < n_u * n_c; k++) {
            cx *co = coef + 5 * k;
            coefficients(ei[k], kga[k], rhoa[k], rhoi[k], co);
            cx a, e, s1, s2;
            wavenumbers(co, w2, &a, &e, &s1, &s2);
            double m1 = hypot(s1.re, s1.im), m2 = hypot(s2.re, s2.im);
            k_max[k] = sqrt(m1 > m2 ? m1 : m2);
        }
    }
    release(b, 6);
    Py_RETURN_NONE;
shape:
    release(b, 6);
    PyErr_SetString(PyExc_ValueError, "segment_coefficients: inconsistent shapes");
    return NULL;
}

/* ------------------------------------------------------------------------ */
/* chain_lines(omega, coef, rhoa, rhoi, length, slot, table, seg_of, nodes, place, out, table_only, lo, hi)
 *
 * omega float64 (real lines) or complex128 (the complex frequency omega - i sigma of an exponential window).
 * Lines lo .. hi - 1 of the chains' receptances into out, line q = c * n_f + i for configuration c;
 * with table_only, instead, the transfer matrices of the shared segments (slot[u] >= 0) at the
 * frequency lines lo .. hi - 1 into table[slot[u], entry, i] (one function for both, so that the
 * closed form has one implementation). */

static PyObject *py_chain_lines(PyObject *self, PyObject *args)
{
    PyObject *o[11];
    int table_only;
    Py_ssize_t lo, hi;
    if (!PyArg_ParseTuple(args, "OOOOOOOOOOOpnn", &o[0], &o[1], &o[2], &o[3], &o[4], &o[5], &o[6], &o[7], &o[8],
                          &o[9], &o[10], &table_only, &lo, &hi))
        return NULL;
    buf_t b[11] = {{0}};
    int cplx = 0; /* omega: float64 (real lines) or complex128 (omega - i sigma: seen through a window) */
    if (get(o[0], &b[0], 'd', 1, 0, "omega")) {
        release(b, 1);
        PyErr_Clear();
        cplx = 1;
        if (get(o[0], &b[0], 'Z', 1, 0, "omega")) {
            release(b, 1);
            PyErr_Clear();
            PyErr_SetString(PyExc_TypeError, "omega: expected a 1-dimensional float64 or complex128 array");
            return NULL;
        }
    }
    if (get(o[1], &b[1], 'Z', 3, 0, "coef") ||
        get(o[2], &b[2], 'd', 2, 0, "rhoa") || get(o[3], &b[3], 'd', 2, 0, "rhoi") ||
        get(o[4], &b[4], 'd', 2, 0, "length") || get(o[5], &b[5], 'q', 1, 0, "slot") ||
        get(o[6], &b[6], 'Z', 3, 1, "table") || get(o[7], &b[7], 'q', 1, 0, "seg_of") ||
        get(o[8], &b[8], 'q', 1, 0, "nodes") || get(o[9], &b[9], 'q', 1, 0, "place") ||
        get(o[10], &b[10], 'Z', 3, 1, "out")) {
        release(b, 11);
        return NULL;
    }
    Py_ssize_t n_f = SHAPE(b[0], 0), n_u = SHAPE(b[1], 0), n_c = SHAPE(b[1], 1);
    Py_ssize_t n_int = SHAPE(b[7], 0), m = SHAPE(b[8], 0);
    const int64_t *slot = b[5].view.buf, *seg_of = b[7].view.buf, *nodes = b[8].view.buf, *place = b[9].view.buf;
    Py_ssize_t n_shared = 0;
    const char *bad = NULL;
    if (SHAPE(b[1], 2) != 5 || SHAPE(b[5], 0) != n_u)
        bad = "coef or slot";
    for (int k = 2; k < 5; k++)
        if (SHAPE(b[k], 0) != n_u || SHAPE(b[k], 1) != n_c)
            bad = "rhoa, rhoi or length";
    for (Py_ssize_t u = 0; u < n_u && !bad; u++)
        if (slot[u] >= n_shared)
            n_shared = slot[u] + 1;
    if (SHAPE(b[6], 0) < n_shared || SHAPE(b[6], 1) != 16 || (n_shared > 0 && SHAPE(b[6], 2) != n_f))
        bad = "table";
    if (SHAPE(b[9], 0) != m)
        bad = "place";
    for (Py_ssize_t k = 0; k < n_int && !bad; k++)
        if (seg_of[k] < 0 || seg_of[k] >= n_u)
            bad = "seg_of";
    for (Py_ssize_t k = 0; k < m && !bad; k++)
        if (nodes[k] < 0 || nodes[k] > n_int || (k > 0 && nodes[k] <= nodes[k - 1]) || place[k] < 0 ||
            place[k] >= m)
            bad = "nodes or place";
    Py_ssize_t n_lines = table_only ? n_f : n_c * n_f;
    if (!table_only && (SHAPE(b[10], 0) != 2 * m || SHAPE(b[10], 1) != 2 * m || SHAPE(b[10], 2) != n_lines))
        bad = "out";
    if (lo < 0 || hi > n_lines || lo > hi)
        bad = "lo, hi";
    if (bad) {
        release(b, 11);
        PyErr_Format(PyExc_ValueError, "chain_lines: inconsistent %s", bad);
        return NULL;
    }
    const double *rhoa = b[2].view.buf, *rhoi = b[3].view.buf, *length = b[4].view.buf;
    const void *omega = b[0].view.buf;
    const cx *coef = b[1].view.buf;
    cx *table = b[6].view.buf, *out = b[10].view.buf;
    Py_ssize_t nu1 = n_u > 0 ? n_u : 1, m1 = m > 0 ? m : 1;
    /* the transfer matrices and the end products of a block (cv), then the segments' wave_t */
    cv *work = aligned_alloc_(sizeof(cv) * (16 * nu1 + 8 * m1) + sizeof(wave_t) * nu1);
    if (!work) {
        release(b, 11);
        return PyErr_NoMemory();
    }
    Py_BEGIN_ALLOW_THREADS
    (cplx ? chain_complex : chain_real)(omega, n_f, coef, rhoa, rhoi, length, n_u, n_c, slot, table, seg_of, n_int,
                                        nodes, place, m, out, table_only, lo, hi, work, work + 16 * nu1,
                                        work + 16 * nu1 + 4 * m1, (wave_t *)(work + 16 * nu1 + 8 * m1));
    Py_END_ALLOW_THREADS
    aligned_free_(work);
    release(b, 11);
    Py_RETURN_NONE;
}

/* ------------------------------------------------------------------------ */
/* The coupling update */

typedef struct {
    const cx *ya, *yb;
    Py_ssize_t wa, wb, n; /* ya is (wa, wa, n), yb (wb, wb, n) */
} pair_t;

/* Block (p, pq) of diag(ya, yb) at one line. */
static inline void block(const pair_t *y, int64_t sp, int64_t p, int64_t sq, int64_t pq, Py_ssize_t line, cx v[4])
{
    if (sp != sq) {
        v[0] = v[1] = v[2] = v[3] = mk(0.0, 0.0);
        return;
    }
    const cx *base = sp == 0 ? y->ya : y->yb;
    Py_ssize_t w = sp == 0 ? y->wa : y->wb;
    Py_ssize_t r = 2 * p, c = 2 * pq, n = y->n;
    v[0] = base[(r * w + c) * n + line];
    v[1] = base[(r * w + c + 1) * n + line];
    v[2] = base[((r + 1) * w + c) * n + line];
    v[3] = base[((r + 1) * w + c + 1) * n + line];
}

/* Entry (dof a of point p, dof b of point pq) of diag(ya, yb) at one line. */
static inline cx entry(const pair_t *y, int64_t sp, int64_t p, int64_t a, int64_t sq, int64_t pq, int64_t b,
                       Py_ssize_t line)
{
    if (sp != sq)
        return mk(0.0, 0.0);
    const cx *base = sp == 0 ? y->ya : y->yb;
    Py_ssize_t w = sp == 0 ? y->wa : y->wb;
    return base[((2 * p + a) * w + 2 * pq + b) * y->n + line];
}

/* couple_lines(ya, yb, a_src, a_idx, b_src, b_idx, src, idx, stiffness, rigid, rows, cols, out, lo, hi) -> bool
 * rows and cols: the entries wanted, as DOF indices 2 k + d over the kept points (k indexes src/idx); out is
 * (len(rows), len(cols), n). */
static PyObject *py_couple_lines(PyObject *self, PyObject *args)
{
    PyObject *o[9];
    long long a_src, a_idx, b_src, b_idx;
    int rigid;
    Py_ssize_t lo, hi;
    if (!PyArg_ParseTuple(args, "OOLLLLOOOpOOOnn", &o[0], &o[1], &a_src, &a_idx, &b_src, &b_idx, &o[2], &o[3], &o[4],
                          &rigid, &o[6], &o[7], &o[5], &lo, &hi))
        return NULL;
    buf_t b[8] = {{0}};
    if (get(o[0], &b[0], 'Z', 3, 0, "ya") || get(o[1], &b[1], 'Z', 3, 0, "yb") ||
        get(o[2], &b[2], 'q', 1, 0, "src") || get(o[3], &b[3], 'q', 1, 0, "idx") ||
        get(o[4], &b[4], 'Z', 3, 0, "stiffness") || get(o[5], &b[5], 'Z', 3, 1, "out") ||
        get(o[6], &b[6], 'q', 1, 0, "rows") || get(o[7], &b[7], 'q', 1, 0, "cols")) {
        release(b, 8);
        return NULL;
    }
    pair_t y = {b[0].view.buf, b[1].view.buf, SHAPE(b[0], 0), SHAPE(b[1], 0), SHAPE(b[0], 2)};
    Py_ssize_t m = SHAPE(b[2], 0), n = y.n, n_k = SHAPE(b[4], 2), nr = SHAPE(b[6], 0), nc = SHAPE(b[7], 0);
    const int64_t *src = b[2].view.buf, *idx = b[3].view.buf, *rows = b[6].view.buf, *cols = b[7].view.buf;
    int ground = b_src < 0;
    const char *bad = NULL;
    if (SHAPE(b[0], 1) != y.wa || SHAPE(b[1], 1) != y.wb || SHAPE(b[1], 2) != n)
        bad = "ya or yb";
    if (SHAPE(b[3], 0) != m || SHAPE(b[5], 0) != nr || SHAPE(b[5], 1) != nc || SHAPE(b[5], 2) != n)
        bad = "src, idx or out";
    for (Py_ssize_t i = 0; i < nr && !bad; i++)
        if (rows[i] < 0 || rows[i] >= 2 * m)
            bad = "rows";
    for (Py_ssize_t j = 0; j < nc && !bad; j++)
        if (cols[j] < 0 || cols[j] >= 2 * m)
            bad = "cols";
    if (SHAPE(b[4], 0) != 2 || SHAPE(b[4], 1) != 2 || (n_k != n && n_k != 1))
        bad = "stiffness";
    if (lo < 0 || hi > n || lo > hi)
        bad = "lo, hi";
#define CHECK_POINT(s, p)                                                            \
    if ((s) == 0 ? ((p) < 0 || 2 * (p) + 1 >= y.wa) : (s) == 1 ? ((p) < 0 || 2 * (p) + 1 >= y.wb) : 1) \
        bad = "point";
    CHECK_POINT(a_src, a_idx)
    if (!ground) {
        CHECK_POINT(b_src, b_idx)
    }
    for (Py_ssize_t i = 0; i < m && !bad; i++) {
        CHECK_POINT(src[i], idx[i])
    }
#undef CHECK_POINT
    if (bad) {
        release(b, 8);
        PyErr_Format(PyExc_ValueError, "couple_lines: inconsistent %s", bad);
        return NULL;
    }
    const cx *stiffness = b[4].view.buf;
    cx *out = b[5].view.buf;
    /* per kept point: its row of U W (4 entries) and its column of B Y (4 entries), and whether a wanted entry
     * needs them */
    size_t mm = (size_t)(m > 0 ? m : 1);
    cx *uw = malloc(sizeof(cx) * 8 * mm);
    char *need = calloc(2 * mm, 1);
    if (!uw || !need) {
        free(uw);
        free(need);
        release(b, 8);
        return PyErr_NoMemory();
    }
    cx *vv = uw + 4 * mm;
    for (Py_ssize_t i = 0; i < nr; i++)
        need[rows[i] >> 1] = 1;
    for (Py_ssize_t j = 0; j < nc; j++)
        need[mm + (cols[j] >> 1)] = 1;
    double bad_re = 0.0, bad_im = 0.0; /* stays 0 while every entry is finite */
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t q = lo; q < hi; q++) {
        cx s[4], x[4], z[4], bb[4];
        block(&y, a_src, a_idx, a_src, a_idx, q, s);
        if (!ground) {
            block(&y, b_src, b_idx, b_src, b_idx, q, bb);
            block(&y, a_src, a_idx, b_src, b_idx, q, x);
            block(&y, b_src, b_idx, a_src, a_idx, q, z);
            for (int k = 0; k < 4; k++)
                s[k] = csub(cadd(s[k], bb[k]), cadd(x[k], z[k]));
        }
        cx e00, e01, e10, e11, k00 = mk(0, 0), k01 = mk(0, 0), k10 = mk(0, 0), k11 = mk(0, 0);
        if (rigid) {
            e00 = s[0]; e01 = s[1]; e10 = s[2]; e11 = s[3];
        } else {
            Py_ssize_t kq = n_k == n ? q : 0;
            k00 = stiffness[0 * n_k + kq];
            k01 = stiffness[1 * n_k + kq];
            k10 = stiffness[2 * n_k + kq];
            k11 = stiffness[3 * n_k + kq];
            e00 = cadd(cadd(mk(1.0, 0.0), cmul(s[0], k00)), cmul(s[1], k10));
            e01 = cadd(cmul(s[0], k01), cmul(s[1], k11));
            e10 = cadd(cmul(s[2], k00), cmul(s[3], k10));
            e11 = cadd(cadd(mk(1.0, 0.0), cmul(s[2], k01)), cmul(s[3], k11));
        }
        cx idet = cinv(det2(e00, e01, e10, e11));
        cx w00 = cmul(e11, idet), w01 = cmul(cneg(e01), idet), w10 = cmul(cneg(e10), idet), w11 = cmul(e00, idet);
        if (!rigid) {
            cx f00 = w00, f01 = w01, f10 = w10, f11 = w11;
            w00 = cadd(cmul(k00, f00), cmul(k01, f10));
            w01 = cadd(cmul(k00, f01), cmul(k01, f11));
            w10 = cadd(cmul(k10, f00), cmul(k11, f10));
            w11 = cadd(cmul(k10, f01), cmul(k11, f11));
        }
        for (Py_ssize_t i = 0; i < m; i++) {
            if (need[i]) {
                cx u[4];
                block(&y, src[i], idx[i], a_src, a_idx, q, u);
                if (!ground) {
                    block(&y, src[i], idx[i], b_src, b_idx, q, x);
                    for (int k = 0; k < 4; k++)
                        u[k] = csub(u[k], x[k]);
                }
                cx *row = uw + 4 * i;
                row[0] = cadd(cmul(u[0], w00), cmul(u[1], w10));
                row[1] = cadd(cmul(u[0], w01), cmul(u[1], w11));
                row[2] = cadd(cmul(u[2], w00), cmul(u[3], w10));
                row[3] = cadd(cmul(u[2], w01), cmul(u[3], w11));
            }
            if (need[mm + i]) {
                cx *v = vv + 4 * i;
                block(&y, a_src, a_idx, src[i], idx[i], q, v);
                if (!ground) {
                    block(&y, b_src, b_idx, src[i], idx[i], q, x);
                    for (int k = 0; k < 4; k++)
                        v[k] = csub(v[k], x[k]);
                }
            }
        }
        for (Py_ssize_t i = 0; i < nr; i++) {
            int64_t pi = rows[i] >> 1, da = rows[i] & 1;
            const cx *row = uw + 4 * pi + 2 * da;
            for (Py_ssize_t j = 0; j < nc; j++) {
                int64_t pj = cols[j] >> 1, db = cols[j] & 1;
                const cx *v = vv + 4 * pj + db;
                cx yy = entry(&y, src[pi], idx[pi], da, src[pj], idx[pj], db, q);
                yy = csub(yy, cadd(cmul(row[0], v[0]), cmul(row[1], v[2])));
                out[(i * nc + j) * n + q] = yy;
                bad_re += yy.re - yy.re;
                bad_im += yy.im - yy.im;
            }
        }
    }
    Py_END_ALLOW_THREADS
    free(uw);
    free(need);
    release(b, 8);
    return PyBool_FromLong(bad_re == 0.0 && bad_im == 0.0);
}

/* ------------------------------------------------------------------------ */
/* The floor of the beam kernel (benchmarks): the transcendental functions the
 * closed form needs, exp(x) and cos(y), sin(y) of both wavenumbers of every
 * segment and line, for the arguments x, y given. */

static PyObject *py_transcendental_floor(PyObject *self, PyObject *args)
{
    PyObject *ox, *oy;
    if (!PyArg_ParseTuple(args, "OO", &ox, &oy))
        return NULL;
    buf_t b[2] = {{0}};
    if (get(ox, &b[0], 'd', 1, 0, "x") || get(oy, &b[1], 'd', 1, 0, "y")) {
        release(b, 2);
        return NULL;
    }
    if (SHAPE(b[0], 0) != SHAPE(b[1], 0)) {
        release(b, 2);
        PyErr_SetString(PyExc_ValueError, "x and y differ in size");
        return NULL;
    }
    const double *x = b[0].view.buf, *y = b[1].view.buf;
    Py_ssize_t n = SHAPE(b[0], 0);
    double acc = 0.0;
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t i = 0; i < n; i++)
        acc += exp(x[i]) + cos(y[i]) + sin(y[i]);
    Py_END_ALLOW_THREADS
    release(b, 2);
    return PyFloat_FromDouble(acc);
}

/* ------------------------------------------------------------------------ */

static PyMethodDef methods[] = {
    {"segment_coefficients", py_segment_coefficients, METH_VARARGS,
     "segment_coefficients(ei, kga, rhoa, rhoi, omega_max, coef, k_max): per-segment constants and largest wavenumber."},
    {"chain_lines", py_chain_lines, METH_VARARGS,
     "chain_lines(omega, coef, rhoa, rhoi, length, slot, table, seg_of, nodes, place, out, table_only, lo, hi)."},
    {"couple_lines", py_couple_lines, METH_VARARGS,
     "couple_lines(ya, yb, a_src, a_idx, b_src, b_idx, src, idx, stiffness, rigid, rows, cols, out, lo, hi) -> all "
     "finite."},
    {"transcendental_floor", py_transcendental_floor, METH_VARARGS,
     "transcendental_floor(x, y): sum of exp(x) + cos(y) + sin(y) (the beam kernel's floor, for benchmarks)."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_ckernels",
                                    "Compiled kernels of substructure (internal; see substructure._kernels).", -1,
                                    methods};

static void init_tables(void)
{
    double f = 1.0;
    for (int k = 0; k < 24; k++) {
        if (k > 0)
            f *= k;
        inv_factorial[k] = 1.0 / f;
    }
    /* |z| <= (1e-18 (2n)!)^(1/n), squared */
    series_bound2[0] = 0.0;
    double fact = 1.0;
    for (int n = 1; n < 12; n++) {
        fact *= (2.0 * n - 1.0) * (2.0 * n);
        double bound = pow(1e-18 * fact, 1.0 / n);
        series_bound2[n] = bound * bound;
    }
}

#ifndef KERNELS_SOURCE_SHA256
#define KERNELS_SOURCE_SHA256 "unknown"
#endif

PyMODINIT_FUNC PyInit__ckernels(void)
{
    init_tables();
    PyObject *m = PyModule_Create(&module);
    if (m == NULL)
        return NULL;
    /* the SHA-256 of this file when it was compiled (setup.py): a checkout can tell a stale build */
    if (PyModule_AddStringConstant(m, "SOURCE_SHA256", KERNELS_SOURCE_SHA256) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
