// bench_interp_calibration: what the interpolation term's calibration (core/uncertainty/
// held_out.h) costs beside the index build it follows, on a session of N
// readings (default 50,000, 101 bands) at random isotropic directions (θi, θo in [0°, 80°],
// φ in [0°, 180°]) with a smooth lobe's spectra. Times, in one run, the index build
// (MakeInterpolator) and the calibration (PredictHeldOut and the fit), --repeat times each, and
// prints the medians and their ratio as one "key=value" line.
//
//   bench_interp_calibration --readings 50000 --method octant --repeat 3
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/interp/interpolator.h"
#include "core/uncertainty/held_out.h"
#include "core/uncertainty/interpolation_calibration.h"

namespace {

using namespace brdf;
using Clock = std::chrono::steady_clock;

std::shared_ptr<interp::SampleSet> MakeSamples(int readings, int bands) {
  auto set = std::make_shared<interp::SampleSet>(3, bands);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> theta(0, 80), phi(0, 180);
  std::vector<double> spectrum(bands);
  for (int i = 0; i < readings; ++i) {
    const double c[3] = {theta(rng), theta(rng), phi(rng)};
    const double d = (c[0] - c[1]) * (c[0] - c[1]) + (180 - c[2]) * (180 - c[2]);
    for (int b = 0; b < bands; ++b) {
      spectrum[b] = (0.2 + 0.001 * b) / 3.14159 + 0.5 * std::exp(-d / 400.0);
    }
    if (!set->Add(i + 1, c, spectrum).ok()) return nullptr;
  }
  return set;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double Seconds(Clock::time_point from) {
  return std::chrono::duration<double>(Clock::now() - from).count();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The interpolation term's calibration beside the index build"};
  int readings = 50000;
  int bands = 101;
  int repeat = 3;
  std::string method_name = "octant";
  app.add_option("--readings", readings, "sample readings")->check(CLI::Range(10, 10000000));
  app.add_option("--bands", bands, "bands per spectrum")->check(CLI::Range(1, 4001));
  app.add_option("--repeat", repeat, "repetitions (median)")->check(CLI::Range(1, 100));
  app.add_option("--method", method_name, "octant or delaunay");
  CLI11_PARSE(app, argc, argv);
  Result<interp::Method> method = interp::ParseMethod(method_name);
  if (!method.ok()) {
    std::fprintf(stderr, "%s\n", method.status().message().c_str());
    return 2;
  }
  const std::shared_ptr<interp::SampleSet> samples = MakeSamples(readings, bands);
  if (!samples) return 1;
  std::vector<double> build, calibrate;
  std::size_t held_out = 0;
  for (int r = 0; r < repeat; ++r) {
    Clock::time_point t0 = Clock::now();
    auto index = interp::MakeInterpolator(*method, samples, interp::Options{});
    build.push_back(Seconds(t0));
    if (!index.ok()) {
      std::fprintf(stderr, "%s\n", index.status().message().c_str());
      return 1;
    }
    t0 = Clock::now();
    const auto points =
        uncertainty::PredictHeldOut(*samples, uncertainty::IndependentOf{}, *method, {});
    const auto fit = uncertainty::FitInterpolationCalibration(points, bands, {});
    calibrate.push_back(Seconds(t0));
    held_out = fit.held_out;
  }
  std::printf("readings=%d method=%s held_out=%zu build_s=%.4f calibration_s=%.4f ratio=%.2f\n",
              readings, method_name.c_str(), held_out, Median(build), Median(calibrate),
              Median(calibrate) / Median(build));
  return 0;
}
