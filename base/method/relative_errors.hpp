// SPDX-License-Identifier: MIT
// Relative errors (METHOD.md Eq. 2-4) and efficiencies (Eq. 5-6) of a configuration.
#pragma once

namespace binocle::method {

// Eq. 2-4: 100 * |measured - truth| / truth, in percent, never negative. NaN (missing)
// when the measured value is missing (NaN) or the truth is not a positive length.
double relativeErrorPercent(double measured, double truth);

// Eq. 5 (reconstructed, METHOD.md): planar efficiency eta2D = 100 - (eps_x + eps_z) / 2,
// clamped to [0, 100]; 0 when an error is missing (the configuration did not deliver it).
double planarEfficiencyPercent(double epsilon_x, double epsilon_z);
// Eq. 6 (reconstructed): stereo efficiency eta3D = 100 - (eps_x + eps_y + eps_z) / 3,
// clamped to [0, 100]; 0 when an error is missing.
double stereoEfficiencyPercent(double epsilon_x, double epsilon_y, double epsilon_z);

// Width X, range Y and height Z of the test panel (mm); NaN where unknown.
struct PanelSize {
    double width_mm, range_mm, height_mm;
};

struct PanelScore {
    bool registered = false; // false: a rejected configuration (errors missing, efficiencies 0)
    double epsilon_x_percent, epsilon_y_percent, epsilon_z_percent; // Eq. 2, 3, 4 (NaN = missing)
    double eta_2d_percent = 0, eta_3d_percent = 0;                  // Eq. 5, 6
};

// Scores the panel read from the cloud (X', Y', Z') against its true size (X, Y, Z).
// registered = false gives the rejected configuration of METHOD.md whatever `measured` holds.
PanelScore scorePanel(const PanelSize &measured, const PanelSize &truth, bool registered);

} // namespace binocle::method
