// hoist/study/stages.hpp -- the stages of a trip and the summary metrics of a run in each.
#pragma once

#include <vector>

#include "hoist/profile.hpp"
#include "hoist/study/metrics.hpp"
#include "hoist/study/runner.hpp"

namespace hoist::study {

/// The stages of a profile for the frequency analysis: "trip" (all), "uniform"
/// (the longest stretch with a = 0 and v != 0) and "decel" (from its end to the
/// end of the profile).  For the paper's Fig. 2 profile: 5-50 s and 50-60 s.
/// Falls back to paperWindows() if the profile has no uniform-velocity stage.
std::vector<Window> stageWindows(const HoistProfile& profile);

/// The summary metrics of one run: peaks and RMS of y_c, theta, the excursion
/// and lambda_0..4 over the trip and each window, and the dominant frequency
/// (FFT and zero crossings) of y_c, theta and lambda_1 in each non-"trip"
/// window.  Names: peak_y_c, rms_theta, peak_lambda_1_uniform, f_y_c_uniform,
/// fzc_theta_decel, osc_y_c_uniform, ... (see metrics.cpp).
MetricSet runMetrics(const RunResult& r, const std::vector<Window>& windows = paperWindows(),
                     const FrequencyOptions& fopt = {});

}  // namespace hoist::study
