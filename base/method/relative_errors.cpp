// SPDX-License-Identifier: MIT
// Relative errors (Eq. 2-4) and planar / stereo efficiencies (Eq. 5-6).
#include "method/relative_errors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace binocle::method {

namespace {
constexpr double kMissing = std::numeric_limits<double>::quiet_NaN();

double efficiency(double meanError) {
    if (!std::isfinite(meanError)) return 0;
    return std::clamp(100.0 - meanError, 0.0, 100.0);
}
} // namespace

// Eq. 2: eps_x = 100 |X' - X| / X; Eq. 3: eps_y = 100 |Y' - Y| / Y; Eq. 4: eps_z = 100 |Z' - Z| / Z.
double relativeErrorPercent(double measured, double truth) {
    if (!std::isfinite(measured) || !std::isfinite(truth) || truth <= 0) return kMissing;
    return 100.0 * std::fabs(measured - truth) / truth;
}

// Eq. 5: eta2D = 100 - (eps_x + eps_z) / 2.
double planarEfficiencyPercent(double epsilon_x, double epsilon_z) { return efficiency((epsilon_x + epsilon_z) / 2); }

// Eq. 6: eta3D = 100 - (eps_x + eps_y + eps_z) / 3.
double stereoEfficiencyPercent(double epsilon_x, double epsilon_y, double epsilon_z) {
    return efficiency((epsilon_x + epsilon_y + epsilon_z) / 3);
}

PanelScore scorePanel(const PanelSize &measured, const PanelSize &truth, bool registered) {
    PanelScore s;
    s.registered = registered;
    s.epsilon_x_percent = s.epsilon_y_percent = s.epsilon_z_percent = kMissing;
    if (!registered) return s; // rejected configuration: errors missing, eta2D = eta3D = 0
    s.epsilon_x_percent = relativeErrorPercent(measured.width_mm, truth.width_mm);
    s.epsilon_y_percent = relativeErrorPercent(measured.range_mm, truth.range_mm);
    s.epsilon_z_percent = relativeErrorPercent(measured.height_mm, truth.height_mm);
    s.eta_2d_percent = planarEfficiencyPercent(s.epsilon_x_percent, s.epsilon_z_percent);
    s.eta_3d_percent = stereoEfficiencyPercent(s.epsilon_x_percent, s.epsilon_y_percent, s.epsilon_z_percent);
    return s;
}

} // namespace binocle::method
