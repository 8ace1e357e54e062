// The JSON and CSV of `estimate rotors` (rotor_estimator.h).
#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "cheval/estim/rotor_estimator.h"

namespace cheval::estim {
namespace {

std::vector<double> Four(const Eigen::Vector4d& v) { return {v[0], v[1], v[2], v[3]}; }
std::string Num(double x) { return fmt::format("{:.10g}", x); }

}  // namespace

std::string RotorEstimateJson(const RotorEstimate& e, const RotorFlight& flight) {
  nlohmann::json spans = nlohmann::json::array();
  for (const auto& [first, last] : flight.flying_spans) spans.push_back({first, last});
  const nlohmann::json out = {{"rotor_error_percent", Four(e.error.percent)},
                              {"flatness_error_percent", Four(e.baseline.percent)},
                              {"rotor_error_rpm", Four(e.error.rpm)},
                              {"flatness_error_rpm", Four(e.baseline.rpm)},
                              {"seconds", e.seconds},
                              {"duration_s", e.duration_s},
                              {"states", e.states},
                              {"segments", e.segments},
                              {"iterations", e.iterations},
                              {"converged", e.converged},
                              {"scored_samples", e.scored_samples},
                              {"dropped_rows", flight.dropped_lines},
                              {"flying_spans", spans},
                              {"clock_offsets_s", e.clock_offsets_s}};
  return out.dump(2) + "\n";
}

std::string RotorStatesCsv(const RotorEstimate& e) {
  std::string text =
      "t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,rotor1,rotor2,rotor3,rotor4,measured1,measured2,measured3,measured4,"
      "baseline1,baseline2,baseline3,baseline4,scored\n";
  for (const RotorStateEstimate& s : e.samples) {
    text += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{}", Num(s.t), Num(s.p.x()), Num(s.p.y()), Num(s.p.z()),
                        Num(s.q.w()), Num(s.q.x()), Num(s.q.y()), Num(s.q.z()), Num(s.v.x()), Num(s.v.y()),
                        Num(s.v.z()), Num(s.w.x()), Num(s.w.y()), Num(s.w.z()));
    for (const Eigen::Vector4d* v : {&s.rotor, &s.measured, &s.baseline}) {
      for (int i = 0; i < 4; ++i) text += "," + Num((*v)[i]);
    }
    text += s.scored ? ",1\n" : ",0\n";
  }
  return text;
}

}  // namespace cheval::estim
