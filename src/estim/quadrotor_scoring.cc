#include "cheval/estim/quadrotor_scoring.h"

#include <cmath>
#include <cstdint>
#include <numbers>

#include <nlohmann/json.hpp>

#include "cheval/common/error.h"
#include "cheval/lie/so3.h"

namespace cheval::estim {

constexpr double kPi = std::numbers::pi;

QuadrotorErrors CompareWithTruth(const QuadrotorEstimate& estimate, const std::vector<QuadrotorTruth>& truth) {
  QuadrotorErrors e;
  Eigen::Vector4d abs_sum = Eigen::Vector4d::Zero(), true_sum = Eigen::Vector4d::Zero();
  double p2 = 0, r2 = 0, v2 = 0;
  size_t k = 0;
  for (const QuadrotorStateEstimate& s : estimate.samples) {
    while (k < truth.size() && truth[k].t < s.t - 1e-9) ++k;
    if (k == truth.size()) break;
    if (std::abs(truth[k].t - s.t) > 1e-9) continue;
    const QuadrotorTruth& g = truth[k];
    abs_sum += (s.rotor - g.rotor).cwiseAbs();
    true_sum += g.rotor;
    p2 += (s.p - g.p).squaredNorm();
    v2 += (s.v - g.v).squaredNorm();
    const double angle = lie::SO3d(Eigen::Matrix3d(s.R.transpose() * g.q.toRotationMatrix())).Log().norm();
    r2 += angle * angle;
    ++e.samples;
  }
  if (e.samples == 0) throw ComputeError("the estimate and the ground truth share no time");
  const double n = e.samples;
  e.rotor_error_rpm = abs_sum / n * 60.0 / (2 * kPi);
  e.rotor_error_percent = 100.0 * abs_sum.cwiseQuotient(true_sum);
  e.position_rmse_m = std::sqrt(p2 / n);
  e.rotation_rmse_deg = std::sqrt(r2 / n) * 180.0 / kPi;
  e.velocity_rmse_mps = std::sqrt(v2 / n);
  return e;
}

std::vector<double> ReportTimes(const QuadrotorData& data) {
  std::vector<double> times;
  for (const QuadrotorTruth& t : data.truth) times.push_back(t.t);
  if (times.empty() && !data.initial.empty()) {
    const double first = data.initial.front().t, last = data.initial.back().t;
    for (int64_t k = 0; first + 0.01 * static_cast<double>(k) <= last; ++k) {
      times.push_back(first + 0.01 * static_cast<double>(k));
    }
  }
  return times;
}

std::vector<QuadrotorTruth> EstimatedStates(const QuadrotorEstimate& estimate) {
  std::vector<QuadrotorTruth> states;
  states.reserve(estimate.samples.size());
  for (const QuadrotorStateEstimate& s : estimate.samples) {
    states.push_back({s.t, s.p, Eigen::Quaterniond(s.R).normalized(), s.v, s.w, s.rotor});
  }
  return states;
}

std::string QuadrotorEstimateJson(const QuadrotorEstimate& e, const QuadrotorErrors* errors) {
  nlohmann::ordered_json j = {{"states", e.states},         {"segments", e.segments}, {"degree", e.degree},
                              {"iterations", e.iterations}, {"seconds", e.seconds},   {"converged", e.converged}};
  if (errors != nullptr) {
    auto four = [](const Eigen::Vector4d& v) { return nlohmann::ordered_json::array({v[0], v[1], v[2], v[3]}); };
    j["rotor_error_rpm"] = four(errors->rotor_error_rpm);
    j["rotor_error_percent"] = four(errors->rotor_error_percent);
    j["position_rmse_m"] = errors->position_rmse_m;
    j["rotation_rmse_deg"] = errors->rotation_rmse_deg;
    j["velocity_rmse_mps"] = errors->velocity_rmse_mps;
  }
  return j.dump(2) + "\n";
}

}  // namespace cheval::estim
