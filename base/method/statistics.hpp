// SPDX-License-Identifier: MIT
// Statistics of repeated tests and of predictors: mean, standard deviation and the 95 %
// confidence interval of the mean (Student t), and Spearman's rank correlation.
#pragma once

#include <vector>

namespace binocle::method {

// Summary of n repeats of one figure. Non-finite samples are left out (a repeat that
// did not register the panel has no εx); n counts the finite ones.
struct Summary {
    int n = 0;
    double mean = 0;
    double sd = 0;          // sample standard deviation (n - 1); 0 when n < 2
    double ci95_low = 0;    // mean -/+ t(0.975, n - 1) * sd / sqrt(n); NaN when n < 2
    double ci95_high = 0;
    double halfWidth() const { return (ci95_high - ci95_low) / 2; }
};

Summary summarize(const std::vector<double> &samples);

// Two-sided Student t quantile: the t with P(|T| < t) = confidence for `dof` degrees of
// freedom (dof >= 1); confidence 0.95 gives 12.706 for 1, 2.262 for 9, 1.960 for infinity.
double studentT(double confidence, int dof);

// Ranks 1..n, ties sharing the mean of the ranks they span.
std::vector<double> ranks(const std::vector<double> &values);

// Spearman's rho between x and y: Pearson's correlation of their ranks (ties averaged).
// Pairs where either value is not finite are left out; NaN when fewer than 3 pairs
// remain or one side is constant.
double spearman(const std::vector<double> &x, const std::vector<double> &y);

} // namespace binocle::method
