// EstimateRotors and IdentifyRotors (rotor_estimator.h): the rotor model (rotor_model.h) on the
// pseudo-spectral problem (problem.h), measured by motion capture, the onboard attitude and body rates.
#include "cheval/estim/rotor_estimator.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include <ceres/covariance.h>
#include <Eigen/Dense>

#include "cheval/cheb/chebyshev.h"
#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "cheval/estim/internal/parametric_collocation_cost.h"
#include "cheval/estim/problem.h"
#include "rotor_internal.h"

namespace cheval::estim {
namespace {

using Problem = PseudoSpectralProblem<RotorModel>;
using Clock = std::chrono::steady_clock;

// The measurements of a sample, whitened, each its own residual block with its own robust loss and
// only the blocks it depends on: the onboard attitude (the rotation error vee(skew(R_measᵀ R)), =
// Log(R_measᵀ R) to second order), the body rate and, when fresh, the motion-capture position.
struct AttitudeMeasurement {
  Eigen::Matrix3d measured_transpose;
  double inv_sigma;
  template <typename T>
  bool operator()(const T* /*x*/, const Eigen::Matrix<T, 3, 3>& R, T* r) const {
    const Eigen::Matrix<T, 3, 3> M = measured_transpose.cast<T>() * R;
    r[0] = T(0.5 * inv_sigma) * (M(2, 1) - M(1, 2));
    r[1] = T(0.5 * inv_sigma) * (M(0, 2) - M(2, 0));
    r[2] = T(0.5 * inv_sigma) * (M(1, 0) - M(0, 1));
    return true;
  }
};

// x's entries [offset, offset + 3) against a measured vector (offset 0: position, 6: body rate).
struct VectorMeasurement {
  Eigen::Vector3d measured;
  int offset;
  double inv_sigma;
  template <typename T>
  bool operator()(const T* x, const Eigen::Matrix<T, 3, 3>& /*R*/, T* r) const {
    for (int i = 0; i < 3; ++i) r[i] = (x[offset + i] - T(measured[i])) * T(inv_sigma);
    return true;
  }
};

// The accelerometer's world-frame specific force a against the trajectory's v' − g (x_dot's entries
// [3, 6): v'), whitened.
struct SpecificForceMeasurement {
  Eigen::Vector3d acceleration;  // a + g: what v' should be
  double inv_sigma;
  template <typename T>
  bool operator()(const T* x_dot, T* r) const {
    for (int i = 0; i < 3; ++i) r[i] = (x_dot[3 + i] - T(acceleration[i])) * T(inv_sigma);
    return true;
  }
};

// (x − x0) / σ on a block of numbers: the weak priors of θ (identification) and the clock offset.
class DiagonalPrior : public internal::BlockCost {
 public:
  DiagonalPrior(double* block, Eigen::VectorXd mean, Eigen::VectorXd sigma)
      : mean_(std::move(mean)), sigma_(std::move(sigma)) {
    AddBlock(block, static_cast<int>(mean_.size()));
    set_num_residuals(static_cast<int>(mean_.size()));
  }
  bool Evaluate(double const* const* p, double* r, double** J) const override {
    const Eigen::Index n = mean_.size();
    Eigen::Map<Eigen::VectorXd>(r, n) = (Eigen::Map<const Eigen::VectorXd>(p[0], n) - mean_).cwiseQuotient(sigma_);
    if (J && J[0]) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> m{J[0], n, n};
      m = sigma_.cwiseInverse().asDiagonal();
    }
    return true;
  }

 private:
  Eigen::VectorXd mean_, sigma_;
};

// (Ω(t) − Ω_measured) / σ with Ω(t) = Σ_k w_k(t) U_k: a measured rotor speed at any time.
class RotorSpeedMeasurement : public internal::BlockCost {
 public:
  RotorSpeedMeasurement(const internal::Segment& segment, Eigen::RowVectorXd w, const Eigen::Vector4d& measured,
                        double sigma)
      : w_(std::move(w)), measured_(measured), inv_sigma_(1.0 / sigma) {
    for (double* control : segment.control) AddBlock(control, 4);
    set_num_residuals(4);
  }
  bool Evaluate(double const* const* p, double* r, double** J) const override {
    Eigen::Vector4d u = -measured_;
    for (int k = 0; k < w_.size(); ++k) u += w_[k] * Eigen::Map<const Eigen::Vector4d>(p[k]);
    Eigen::Map<Eigen::Vector4d>{r} = inv_sigma_ * u;
    for (int k = 0; J && k < w_.size(); ++k) {
      if (J[k]) Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>{J[k]} = inv_sigma_ * w_[k] * Eigen::Matrix4d::Identity();
    }
    return true;
  }

 private:
  Eigen::RowVectorXd w_;
  Eigen::Vector4d measured_;
  double inv_sigma_;
};

RotorThetaVector PriorSigma() {
  RotorThetaVector s = RotorThetaVector::Constant(100.0);
  s.head<8>().setOnes();
  return s;
}

// The flying spans long enough to score, as [first, last] sample indices.
std::vector<std::pair<size_t, size_t>> Spans(const RotorFlight& flight, double margin_s) {
  std::vector<std::pair<size_t, size_t>> out;
  const std::vector<RotorSample>& s = flight.samples;
  for (size_t i = 0; i < s.size();) {
    if (!s[i].flying) {
      ++i;
      continue;
    }
    size_t j = i;
    while (j + 1 < s.size() && s[j + 1].flying) ++j;
    if (s[j].t - s[i].t > 2 * margin_s + 0.1) out.push_back({i, j});
    i = j + 1;
  }
  if (out.empty()) {
    throw ComputeError(fmt::format("{}: no flying span (is_flying = 1) longer than {} s", flight.path,
                                   2 * margin_s + 0.1));
  }
  return out;
}

// The problem over samples [first, last], initial values set, measurements added (no dynamics yet).
// With `clock_offset` (a parameter block, seconds), the positions are stamped δ behind the problem's
// (the onboard samples') time (DelayedPositionCost); without it they share it.
std::unique_ptr<Problem> BuildProblem(const RotorFlight& flight, size_t first, size_t last, const RotorModel& model,
                                      const RotorEstimateOptions& o, bool measured_rotors,
                                      const ceres::LossFunction* loss, double* clock_offset = nullptr) {
  const std::vector<RotorSample>& s = flight.samples;
  const double t0 = s[first].t, t1 = s[last].t;
  const int segments = SegmentCount("RotorEstimateOptions", t1 - t0, o.segment_s, o.degree);
  std::vector<double> breakpoints(segments + 1);
  for (int k = 0; k <= segments; ++k) breakpoints[k] = t0 + (t1 - t0) * k / segments;
  breakpoints.back() = t1;
  auto problem = std::make_unique<Problem>(model, breakpoints, o.degree);
  const Eigen::Vector3d g(0, 0, -model.nominal.gravity_mps2);
  for (int n = 0; n < problem->num_nodes(); ++n) {
    const double t = problem->NodeTime(n);
    const rotor_internal::KinematicFit fit = rotor_internal::FitPosition(flight, t, o.baseline_window_s);
    const RotorSample at = rotor_internal::SampleAt(flight, t);
    Eigen::Vector3d w, w_dot;
    rotor_internal::FitRate(flight, t, o.baseline_window_s, &w, &w_dot);
    const Eigen::Matrix3d R = at.q.toRotationMatrix();
    Eigen::VectorXd x(9);
    x << fit.p, fit.v, at.w;
    const Eigen::Vector4d rotor =
        measured_rotors ? at.rotor
                        : rotor_internal::InvertMixer(model.nominal, model.theta, (R.transpose() * (fit.a - g)).z(),
                                                      R.transpose() * fit.v, at.w, w_dot);
    problem->SetNode(n, x, R, rotor);
  }
  problem->SetChartReferences();
  // One residual block per sensor and segment (AddMeasurements), a Huber loss per sample.
  std::vector<double> times, position_times;
  std::vector<AttitudeMeasurement> attitudes;
  std::vector<VectorMeasurement> rates, positions;
  for (size_t i = first; i <= last; ++i) {
    times.push_back(s[i].t);
    attitudes.push_back({s[i].q.toRotationMatrix().transpose(), 1.0 / o.attitude_sigma_rad});
    rates.push_back({s[i].w, 6, 1.0 / o.rate_sigma_radps});
    if (s[i].fresh_position) {
      position_times.push_back(s[i].t);
      positions.push_back({s[i].p, 0, 1.0 / o.position_sigma_m});
    }
  }
  problem->AddMeasurements(times, std::move(attitudes), 3, 3, {}, loss);
  problem->AddMeasurements(times, std::move(rates), 3, 3, {2}, loss, false);
  if (o.use_accelerometer && !measured_rotors) {
    std::vector<SpecificForceMeasurement> forces;
    for (size_t i = first; i <= last; ++i) forces.push_back({s[i].accel + g, 1.0 / o.accelerometer_sigma_mps2});
    problem->AddDerivativeMeasurements(times, std::move(forces), 3, 3, {1}, loss);
  }
  if (clock_offset == nullptr) {
    problem->AddMeasurements(position_times, std::move(positions), 3, 3, {0}, loss, false);
    return problem;
  }
  std::vector<Eigen::Vector3d> measured;
  for (const VectorMeasurement& position : positions) measured.push_back(position.measured);
  problem->AddDelayedPositions(position_times, measured, 0, 1, o.position_sigma_m, loss, clock_offset);
  // A weak prior, not bounds (Ceres' bounds double the Jacobian evaluations): it holds δ near 0
  // where the motion cannot tell it (a hover) and leaves it free where it can.
  problem->AddPrior(std::make_unique<DiagonalPrior>(clock_offset, Eigen::VectorXd::Zero(1),
                                                    Eigen::VectorXd::Constant(1, kClockOffsetPriorSigmaS)));
  return problem;
}

Eigen::Matrix<double, 12, 1> CollocationSigma(const RotorEstimateOptions& o) {
  Eigen::Matrix<double, 12, 1> sigma;
  sigma << Eigen::Vector3d::Constant(o.sigma_position_rate), Eigen::Vector3d::Constant(o.sigma_acceleration),
      Eigen::Vector3d::Constant(o.sigma_angular_acceleration), Eigen::Vector3d::Constant(o.sigma_rotation_rate);
  return sigma;
}

// The collocation defects at every node: p' and R' by the model's kinematics (CollocationCost), v'
// and ω' by ParametricCollocationCost (the rotor accelerations; θ a parameter block when kIdentify,
// else the values `theta` points to).
template <bool kIdentify>
void AddDynamics(Problem& problem, const RotorModel& model, const RotorEstimateOptions& o, double* theta) {
  const Eigen::MatrixXd D = cheb::DifferentiationMatrix(o.degree);
  const Eigen::Matrix<double, 12, 1> sigma = CollocationSigma(o);
  using Dynamics = internal::ParametricCollocationCost<kIdentify>;
  for (int s = 0; s < problem.num_segments(); ++s) {
    const internal::Segment segment = problem.SegmentOf(s);
    for (int j = 0; j <= o.degree; ++j) {
      problem.AddPrior(std::make_unique<internal::CollocationCost<RotorModel>>(model, segment, D, j, 0, sigma));
      problem.AddPrior(std::make_unique<internal::CollocationCost<RotorModel>>(model, segment, D, j, 3, sigma));
      problem.AddPrior(std::make_unique<Dynamics>(model.nominal, segment, D, j, 1, o.sigma_acceleration, theta));
      problem.AddPrior(std::make_unique<Dynamics>(model.nominal, segment, D, j, 2, o.sigma_angular_acceleration, theta));
    }
  }
}

ceres::Solver::Options SolverOptions(const RotorEstimateOptions& o) {
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = o.max_iterations;
  solver.num_threads = o.threads;
  solver.logging_type = ceres::SILENT;
  solver.initial_trust_region_radius = 1e8;
  solver.function_tolerance = o.function_tolerance;
  return solver;
}

}  // namespace

void RotorEstimateOptions::Validate() const {
  const OptionCheck check("RotorEstimateOptions");
  const auto positive = [](double x) { return x > 0 && std::isfinite(x); };
  check(degree >= 2 && degree <= 20, "degree", "must be in [2, 20], got {}", degree);
  check(positive(segment_s), "segment_s", "must be a positive number of seconds, got {}", segment_s);
  check(positive(position_sigma_m), "position_sigma_m", "must be > 0, got {}", position_sigma_m);
  check(positive(attitude_sigma_rad), "attitude_sigma_rad", "must be > 0, got {}", attitude_sigma_rad);
  check(positive(rate_sigma_radps), "rate_sigma_radps", "must be > 0, got {}", rate_sigma_radps);
  check(positive(rotor_sigma_radps), "rotor_sigma_radps", "must be > 0, got {}", rotor_sigma_radps);
  check(positive(huber), "huber", "must be > 0, got {}", huber);
  check(positive(sigma_position_rate), "sigma_position_rate", "must be > 0, got {}", sigma_position_rate);
  check(positive(sigma_acceleration), "sigma_acceleration", "must be > 0, got {}", sigma_acceleration);
  check(positive(sigma_angular_acceleration), "sigma_angular_acceleration", "must be > 0, got {}",
        sigma_angular_acceleration);
  check(positive(sigma_rotation_rate), "sigma_rotation_rate", "must be > 0, got {}", sigma_rotation_rate);
  check(positive(sigma_rotor_rate), "sigma_rotor_rate", "must be > 0, got {}", sigma_rotor_rate);
  check(positive(accelerometer_sigma_mps2), "accelerometer_sigma_mps2", "must be > 0, got {}", accelerometer_sigma_mps2);
  check(positive(baseline_window_s), "baseline_window_s", "must be > 0, got {}", baseline_window_s);
  check(identification_piece_s >= 1 && std::isfinite(identification_piece_s), "identification_piece_s",
        "must be at least 1 s, got {}", identification_piece_s);
  check(score_margin_s >= 0 && std::isfinite(score_margin_s), "score_margin_s", "must be >= 0, got {}", score_margin_s);
  check(positive(function_tolerance), "function_tolerance", "must be > 0, got {}", function_tolerance);
  check(max_iterations >= 1, "max_iterations", "must be >= 1, got {}", max_iterations);
  check(threads >= 1, "threads", "must be >= 1, got {}", threads);
}

RotorEstimate EstimateRotors(const RotorFlight& flight, const RotorVehicle& vehicle, const RotorEstimateOptions& o) {
  o.Validate();
  RotorEstimate out;
  const std::vector<std::pair<size_t, size_t>> spans = Spans(flight, o.score_margin_s);
  const RotorModel model{vehicle.nominal, vehicle.theta};
  const ceres::HuberLoss huber(o.huber);
  std::vector<Eigen::Vector4d> estimate(flight.samples.size(), Eigen::Vector4d::Zero());
  const auto start = Clock::now();
  out.converged = true;
  for (const auto& [first, last] : spans) {
    double clock_offset = 0;
    std::unique_ptr<Problem> problem =
        BuildProblem(flight, first, last, model, o, false, &huber, o.estimate_clock_offset ? &clock_offset : nullptr);
    RotorThetaVector theta = vehicle.theta;
    AddDynamics<false>(*problem, model, o, theta.data());
    problem->AddControlSmoothnessPrior(1, o.sigma_rotor_rate);
    const ceres::Solver::Summary summary = problem->Solve(SolverOptions(o));
    out.converged = out.converged && summary.termination_type == ceres::CONVERGENCE;
    out.iterations += static_cast<int>(summary.iterations.size()) - 1;
    out.states += problem->num_nodes();
    out.segments += problem->num_segments();
    out.duration_s += flight.samples[last].t - flight.samples[first].t;
    out.clock_offsets_s.push_back(clock_offset);
    for (size_t i = first; i <= last; ++i) {
      // The flight's stamps are the motion capture's (and the rotor telemetry's): the problem's time is δ later.
      const StateSample x = problem->Interpolate(
          std::clamp(flight.samples[i].t + clock_offset, problem->start_time(), problem->end_time()));
      estimate[i] = x.control.head<4>();
      RotorStateEstimate e;
      e.t = flight.samples[i].t;
      e.p = x.vector.segment<3>(0);
      e.v = x.vector.segment<3>(3);
      e.w = x.vector.segment<3>(6);
      e.q = Eigen::Quaterniond(x.rotation);
      e.rotor = estimate[i];
      e.measured = flight.samples[i].rotor;
      out.samples.push_back(e);
    }
  }
  out.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const std::vector<Eigen::Vector4d> baseline =
      FlatnessRotorSpeeds(flight, vehicle.nominal, RotorNominal::PublishedTheta(), o.baseline_window_s);
  const std::vector<size_t> scored = ScoredSamples(flight, o.score_margin_s);
  out.scored_samples = static_cast<int>(scored.size());
  out.error = ScoreRotors(flight, estimate, scored);
  out.baseline = ScoreRotors(flight, baseline, scored);
  size_t k = 0;
  for (const auto& [first, last] : spans) {
    for (size_t i = first; i <= last; ++i, ++k) {
      out.samples[k].baseline = baseline[i];
      out.samples[k].scored = std::binary_search(scored.begin(), scored.end(), i);
    }
  }
  return out;
}

namespace {

using ThetaMatrix = Eigen::Matrix<double, kRotorThetaSize, kRotorThetaSize>;

// θ from samples [first, last] of a flight: the trajectory, its rotor speeds and θ jointly, the rotor
// speeds measured.
RotorIdentification IdentifyPiece(const RotorFlight& flight, size_t first, size_t last, const RotorVehicle& base,
                                  const RotorEstimateOptions& o) {
  const auto start = Clock::now();
  const RotorModel model{base.nominal, base.theta};
  const ceres::HuberLoss huber(o.huber);
  RotorThetaVector theta = base.theta;
  RotorIdentification id;
  // J_z is held: every yaw torque (k_M Ω², the rotors' reaction, τ0_z) is seen only through its ratio
  // to J_z (docs/estimator_real_data.md).
  ceres::SubsetManifold hold_yaw_inertia(kRotorThetaSize, {kThetaInertiaX + 2});
  // The onboard clock's offset δ from the motion capture's, which the rotor telemetry shares
  // (docs/estimator_real_data.md, "Two clocks"): free in the positions; the telemetry's rows sit at
  // t + δ of the pass before (two passes, the second from the first's δ and θ).
  double clock_offset = 0;
  std::unique_ptr<Problem> problem;
  ceres::Solver::Summary summary;
  for (int pass = 0; pass < (o.estimate_clock_offset ? 2 : 1); ++pass) {
    const double telemetry_offset = clock_offset;
    problem = BuildProblem(flight, first, last, model, o, true, &huber, o.estimate_clock_offset ? &clock_offset : nullptr);
    AddDynamics<true>(*problem, model, o, theta.data());
    problem->AddPrior(std::make_unique<DiagonalPrior>(theta.data(), RotorNominal::PublishedTheta(), PriorSigma()));
    problem->ceres_problem().SetManifold(theta.data(), &hold_yaw_inertia);
    for (int i = 0; i < 2; ++i) {  // a rigid body's inertia is positive: at least 1 % of the published one
      problem->ceres_problem().SetParameterLowerBound(theta.data(), kThetaInertiaX + i, 0.01);
    }
    for (size_t i = first; i <= last; ++i) {
      const internal::TimeRow row = problem->RowAt(
          std::clamp(flight.samples[i].t + telemetry_offset, problem->start_time(), problem->end_time()));
      problem->AddPrior(std::make_unique<RotorSpeedMeasurement>(problem->SegmentOf(row.segment), row.w,
                                                                flight.samples[i].rotor, o.rotor_sigma_radps));
    }
    summary = problem->Solve(SolverOptions(o));
  }
  id.clock_offset_s = clock_offset;
  id.converged = summary.termination_type == ceres::CONVERGENCE;
  ceres::Covariance::Options copt;
  copt.num_threads = o.threads;
  ceres::Covariance covariance(copt);
  const std::vector<std::pair<const double*, const double*>> blocks = {{theta.data(), theta.data()}};
  if (!covariance.Compute(blocks, &problem->ceres_problem())) {
    throw ComputeError(fmt::format("{}: the covariance of the identified parameters could not be computed (the "
                                   "problem is rank-deficient)",
                                   flight.path));
  }
  // In θ's tangent (J_z held: one entry fewer), spread into θ with zeros for the held entry. The
  // ambient-space getter lifts through Eigen temporaries inside Ceres, whose heap blocks an
  // AddressSanitizer build of cheval allocates and frees with two different alignments.
  constexpr int kFree = kRotorThetaSize - 1;
  Eigen::Matrix<double, kFree, kFree, Eigen::RowMajor> tangent;
  covariance.GetCovarianceBlockInTangentSpace(theta.data(), theta.data(), tangent.data());
  id.covariance.setZero();
  const auto ambient = [](int k) { return k < kThetaInertiaX + 2 ? k : k + 1; };
  for (int a = 0; a < kFree; ++a) {
    for (int b = 0; b < kFree; ++b) id.covariance(ambient(a), ambient(b)) = tangent(a, b);
  }
  // Degrees of freedom: every measurement's rows (the compressed blocks return fewer) less θ and the states.
  id.reduced_chi2 = 2.0 * summary.final_cost /
                    std::max(1, problem->num_represented_rows() - summary.num_effective_parameters_reduced);
  id.covariance *= std::max(1.0, id.reduced_chi2);
  id.theta = theta;
  id.pieces = 1;
  id.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return id;
}

// The flying spans cut into pieces of about piece_s (at least one per span), as [first, last].
std::vector<std::pair<size_t, size_t>> Pieces(const RotorFlight& flight, const RotorEstimateOptions& o) {
  std::vector<std::pair<size_t, size_t>> out;
  for (const auto& [first, last] : Spans(flight, o.score_margin_s)) {
    const double t0 = flight.samples[first].t, length = flight.samples[last].t - t0;
    const int n = std::max(1, static_cast<int>(std::floor(length / o.identification_piece_s)));
    size_t begin = first;
    for (int k = 1; k <= n; ++k) {
      size_t end = last;
      if (k < n) {
        const double cut = t0 + length * k / n;
        end = begin;
        while (end + 1 <= last && flight.samples[end + 1].t <= cut) ++end;
      }
      out.push_back({begin, end});
      begin = end + 1;
    }
  }
  return out;
}

}  // namespace

RotorThetaVector BirgeRatios(const std::vector<RotorIdentification>& groups, const RotorThetaVector& theta) {
  RotorThetaVector ratio = RotorThetaVector::Ones();
  if (groups.size() < 2) return ratio;
  for (int i = 0; i < kRotorThetaSize; ++i) {
    if (groups.front().covariance(i, i) == 0) continue;  // held
    double q = 0;
    for (const RotorIdentification& g : groups) q += (g.theta[i] - theta[i]) * (g.theta[i] - theta[i]) / g.covariance(i, i);
    ratio[i] = std::max(1.0, std::sqrt(q / static_cast<double>(groups.size() - 1)));
  }
  return ratio;
}

RotorIdentification CombineIdentifications(const std::vector<RotorIdentification>& pieces) {
  if (pieces.empty()) throw UsageError("no identification to combine");
  // The product of the pieces' Gaussians, then each parameter's σ scaled by its Birge ratio
  // sqrt(Q / (k − 1)), Q = Σ (θ_piece − θ)² / σ²_piece (Cochran's Q): how much farther apart the pieces
  // are than their own σ says. The correlations are kept.
  // Entries held in every piece (zero variance) are carried over as they are.
  std::vector<int> free;
  for (int i = 0; i < kRotorThetaSize; ++i) {
    if (pieces.front().covariance(i, i) > 0) free.push_back(i);
  }
  const int n = static_cast<int>(free.size());
  const auto reduce = [&](const ThetaMatrix& m) {
    Eigen::MatrixXd r(n, n);
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) r(a, b) = m(free[a], free[b]);
    }
    return r;
  };
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd eta = Eigen::VectorXd::Zero(n);
  RotorIdentification out;
  out.theta = pieces.front().theta;
  for (const RotorIdentification& p : pieces) {
    const Eigen::MatrixXd lambda = reduce(p.covariance).ldlt().solve(Eigen::MatrixXd::Identity(n, n));
    Eigen::VectorXd theta(n);
    for (int a = 0; a < n; ++a) theta[a] = p.theta[free[a]];
    information += lambda;
    eta += lambda * theta;
    out.reduced_chi2 = std::max(out.reduced_chi2, p.reduced_chi2);
    out.clock_offset_s += p.clock_offset_s / static_cast<double>(pieces.size());
    out.seconds += p.seconds;
    out.pieces += p.pieces;
  }
  const Eigen::MatrixXd covariance = information.ldlt().solve(Eigen::MatrixXd::Identity(n, n));
  const Eigen::VectorXd theta = covariance * eta;
  out.covariance.setZero();
  for (int a = 0; a < n; ++a) {
    out.theta[free[a]] = theta[a];
    for (int b = 0; b < n; ++b) out.covariance(free[a], free[b]) = covariance(a, b);
  }
  out.dispersion = BirgeRatios(pieces, out.theta);
  out.covariance = out.dispersion.asDiagonal() * out.covariance * out.dispersion.asDiagonal();
  out.converged = std::all_of(pieces.begin(), pieces.end(), [](const RotorIdentification& p) { return p.converged; });
  return out;
}

RotorVehicle IdentifyRotors(const std::vector<RotorFlight>& flights, const RotorVehicle& base,
                            const RotorEstimateOptions& options, std::vector<RotorIdentification>* per_flight) {
  options.Validate();
  if (flights.empty()) throw UsageError("identification needs at least one flight");
  RotorVehicle out = base;
  out.training.clear();
  std::vector<RotorIdentification> all, each;
  for (const RotorFlight& flight : flights) {
    std::vector<RotorIdentification> pieces;
    for (const auto& [first, last] : Pieces(flight, options)) pieces.push_back(IdentifyPiece(flight, first, last, base, options));
    all.insert(all.end(), pieces.begin(), pieces.end());
    out.training.push_back(flight.path);
    each.push_back(CombineIdentifications(pieces));
  }
  if (per_flight) per_flight->insert(per_flight->end(), each.begin(), each.end());
  const RotorIdentification combined = CombineIdentifications(all);
  out.theta = combined.theta;
  // Between flights: a flight's pieces may agree with each other and not with another flight's (τ0,
  // k_m1 and d_xy of square against the other two, docs/estimator_real_data.md); σ is widened by the
  // flights' own Birge ratio too, each flight with its σ from its own pieces.
  out.theta_sigma = combined.covariance.diagonal().cwiseSqrt().cwiseProduct(BirgeRatios(each, combined.theta));
  return out;
}

}  // namespace cheval::estim
