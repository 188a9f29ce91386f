// SPDX-License-Identifier: MIT
// Mean, standard deviation, Student t confidence intervals, Spearman's rho.
#include "method/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace binocle::method {

namespace {

// Continued fraction of the regularised incomplete beta function (Numerical Recipes,
// betacf): converges fast for x < (a + 1) / (a + b + 2).
double betaFraction(double a, double b, double x) {
    const double tiny = 1e-300;
    double c = 1, d = 1 - (a + b) * x / (a + 1);
    if (std::fabs(d) < tiny) d = tiny;
    d = 1 / d;
    double h = d;
    for (int m = 1; m <= 300; ++m) {
        const double m2 = 2.0 * m;
        double aa = m * (b - m) * x / ((a + m2 - 1) * (a + m2));
        d = 1 + aa * d;
        if (std::fabs(d) < tiny) d = tiny;
        c = 1 + aa / c;
        if (std::fabs(c) < tiny) c = tiny;
        d = 1 / d;
        h *= d * c;
        aa = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1));
        d = 1 + aa * d;
        if (std::fabs(d) < tiny) d = tiny;
        c = 1 + aa / c;
        if (std::fabs(c) < tiny) c = tiny;
        d = 1 / d;
        const double step = d * c;
        h *= step;
        if (std::fabs(step - 1) < 1e-15) break;
    }
    return h;
}

double incompleteBeta(double a, double b, double x) {
    if (x <= 0) return 0;
    if (x >= 1) return 1;
    const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x));
    if (x < (a + 1) / (a + b + 2)) return front * betaFraction(a, b, x) / a;
    return 1 - front * betaFraction(b, a, 1 - x) / b;
}

// P(|T| < t) for Student's t with `dof` degrees of freedom.
double twoSidedCdf(double t, double dof) { return 1 - incompleteBeta(dof / 2, 0.5, dof / (dof + t * t)); }

} // namespace

double studentT(double confidence, int dof) {
    if (!(confidence > 0 && confidence < 1)) throw std::invalid_argument("studentT: confidence must lie in (0, 1)");
    if (dof < 1) throw std::invalid_argument("studentT: degrees of freedom must be >= 1");
    double lo = 0, hi = 1;
    while (twoSidedCdf(hi, dof) < confidence) hi *= 2; // dof 1, 99.9 %: 637
    for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
        const double mid = (lo + hi) / 2;
        (twoSidedCdf(mid, dof) < confidence ? lo : hi) = mid;
    }
    return (lo + hi) / 2;
}

Summary summarize(const std::vector<double> &samples) {
    std::vector<double> v;
    for (double s : samples)
        if (std::isfinite(s)) v.push_back(s);
    Summary r;
    r.n = static_cast<int>(v.size());
    if (v.empty()) {
        r.mean = r.sd = r.ci95_low = r.ci95_high = NAN;
        return r;
    }
    r.mean = std::accumulate(v.begin(), v.end(), 0.0) / r.n;
    if (r.n < 2) {
        r.sd = 0;
        r.ci95_low = r.ci95_high = NAN;
        return r;
    }
    double ss = 0;
    for (double s : v) ss += (s - r.mean) * (s - r.mean);
    r.sd = std::sqrt(ss / (r.n - 1));
    const double half = studentT(0.95, r.n - 1) * r.sd / std::sqrt(static_cast<double>(r.n));
    r.ci95_low = r.mean - half;
    r.ci95_high = r.mean + half;
    return r;
}

std::vector<double> ranks(const std::vector<double> &values) {
    std::vector<size_t> order(values.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return values[a] < values[b]; });
    std::vector<double> r(values.size());
    for (size_t i = 0; i < order.size();) {
        size_t j = i;
        while (j + 1 < order.size() && values[order[j + 1]] == values[order[i]]) ++j;
        const double shared = (i + j) / 2.0 + 1; // mean of ranks i+1 .. j+1
        for (size_t k = i; k <= j; ++k) r[order[k]] = shared;
        i = j + 1;
    }
    return r;
}

double spearman(const std::vector<double> &x, const std::vector<double> &y) {
    if (x.size() != y.size()) throw std::invalid_argument("spearman: x and y differ in length");
    std::vector<double> a, b;
    for (size_t i = 0; i < x.size(); ++i)
        if (std::isfinite(x[i]) && std::isfinite(y[i])) {
            a.push_back(x[i]);
            b.push_back(y[i]);
        }
    if (a.size() < 3) return NAN;
    const std::vector<double> ra = ranks(a), rb = ranks(b);
    const double n = static_cast<double>(ra.size());
    const double ma = std::accumulate(ra.begin(), ra.end(), 0.0) / n, mb = std::accumulate(rb.begin(), rb.end(), 0.0) / n;
    double sab = 0, saa = 0, sbb = 0;
    for (size_t i = 0; i < ra.size(); ++i) {
        sab += (ra[i] - ma) * (rb[i] - mb);
        saa += (ra[i] - ma) * (ra[i] - ma);
        sbb += (rb[i] - mb) * (rb[i] - mb);
    }
    if (saa == 0 || sbb == 0) return NAN;
    return sab / std::sqrt(saa * sbb);
}

} // namespace binocle::method
