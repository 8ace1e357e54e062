#include "cheval/estim/quadrotor_estimator.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include <Eigen/Dense>

#include "cheval/cheb/chebyshev.h"
#include "cheval/common/error.h"
#include "cheval/common/options.h"
#include "cheval/estim/problem.h"
#include "cheval/lie/so3.h"
#include "thrust_acceleration_prior.h"

namespace cheval::estim {
namespace {

using Problem = PseudoSpectralProblem<QuadrotorModel>;

// Pixel residuals of the landmarks of one frame, whitened by the pixel σ.
struct FrameProjection {
  Eigen::Matrix3d camera_from_body;
  double fx, fy, cx, cy, inv_sigma;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;

  template <typename T>
  bool operator()(const T* x, const Eigen::Matrix<T, 3, 3>& R, T* r) const {
    const Eigen::Matrix<T, 3, 1> p(x[0], x[1], x[2]);
    const Eigen::Matrix<T, 3, 3> C = camera_from_body.cast<T>() * R.transpose();
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Matrix<T, 3, 1> c = C * (points[i].cast<T>() - p);
      if (c.z() < T(1e-3)) return false;  // behind the camera: Ceres rejects the step
      r[2 * i] = (T(fx) * c.x() / c.z() + T(cx) - T(pixels[i].x())) * T(inv_sigma);
      r[2 * i + 1] = (T(fy) * c.y() / c.z() + T(cy) - T(pixels[i].y())) * T(inv_sigma);
    }
    return true;
  }
};

// The front end's pose at t, interpolated (linear / slerp) between its samples.
struct InitialTrajectory {
  const std::vector<PoseSample>& poses;
  PoseSample At(double t) const {
    auto it = std::lower_bound(poses.begin(), poses.end(), t, [](const PoseSample& s, double v) { return s.t < v; });
    if (it == poses.begin()) return poses.front();
    if (it == poses.end()) return poses.back();
    const PoseSample& b = *it;
    const PoseSample& a = *(it - 1);
    const double f = b.t > a.t ? (t - a.t) / (b.t - a.t) : 0.0;
    return {t, a.p + f * (b.p - a.p), a.q.slerp(f, b.q)};
  }
};

}  // namespace

QuadrotorStateEstimate FlatnessInitialState(const QuadrotorParameters& q, const std::vector<PoseSample>& poses,
                                            double t, double window_s) {
  if (poses.size() < 3) throw ComputeError("the flatness-based initialisation needs at least 3 poses");
  if (!(window_s > 0)) throw UsageError(fmt::format("the initialisation window must be > 0 s, got {}", window_s));
  const double first = poses.front().t, last = poses.back().t;
  const double half = 0.5 * window_s;
  const double center = last - first <= window_s ? 0.5 * (first + last) : std::clamp(t, first + half, last - half);
  auto lo = std::lower_bound(poses.begin(), poses.end(), center - half - 1e-9,
                             [](const PoseSample& s, double v) { return s.t < v; });
  auto hi = std::upper_bound(poses.begin(), poses.end(), center + half + 1e-9,
                             [](double v, const PoseSample& s) { return v < s.t; });
  while (hi - lo < 3) {  // a window with too few poses: widen it by one pose on each side
    if (lo != poses.begin()) --lo;
    if (hi != poses.end()) ++hi;
  }
  const int n = static_cast<int>(hi - lo);
  const Eigen::Quaterniond q_t = InitialTrajectory{poses}.At(t).q;
  const lie::SO3d R_t(q_t);
  Eigen::MatrixXd A(n, 3), P(n, 3), Phi(n, 3);
  for (int i = 0; i < n; ++i) {
    const PoseSample& s = *(lo + i);
    const double tau = s.t - t;
    A.row(i) << 1.0, tau, tau * tau;
    P.row(i) = s.p.transpose();
    Phi.row(i) = lie::SO3d(s.q).Minus(R_t).transpose();
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  const Eigen::MatrixXd c = qr.solve(P);                                     // p(t + τ) ≈ c0 + c1 τ + c2 τ²
  const Eigen::MatrixXd b = A.leftCols(2).colPivHouseholderQr().solve(Phi);  // φ(t + τ) ≈ b0 + b1 τ
  QuadrotorStateEstimate out;
  out.t = t;
  out.p = c.row(0).transpose();
  out.v = c.row(1).transpose();
  out.w = b.row(1).transpose();
  out.R = q_t.toRotationMatrix();
  const Eigen::Vector3d a = 2.0 * c.row(2).transpose();
  const Eigen::Vector3d force =
      q.mass_kg * (a + Eigen::Vector3d(0, 0, q.gravity_mps2)) + q.drag_coefficient * out.v.norm() * out.v;
  const double thrust = force.dot(out.R.col(2));
  const Eigen::Vector3d Jw = q.inertia_kgm2.cwiseProduct(out.w);
  const Eigen::Vector3d tau = out.w.cross(Jw);
  const double arm = q.arm_m, k = q.moment_coefficient / q.thrust_coefficient;
  Eigen::Matrix4d mix;  // [T, τx, τy, τz] = mix · f (the motor layout of models.h)
  mix << 1, 1, 1, 1,            //
      arm, arm, -arm, -arm,     //
      -arm, arm, arm, -arm,     //
      -k, k, -k, k;
  const Eigen::Vector4d f = mix.fullPivLu().solve(Eigen::Vector4d(thrust, tau.x(), tau.y(), tau.z()));
  for (int i = 0; i < 4; ++i) {
    out.rotor[i] = std::min(std::sqrt(std::max(f[i], 0.0) / q.thrust_coefficient), q.max_rotor_speed_radps);
  }
  return out;
}

std::vector<double> AdaptiveRotorPriorSigma(const std::vector<double>& energy, int degree, int controls) {
  if (degree < 1 || controls < 1) throw UsageError("the adaptive rotor prior needs degree >= 1 and controls >= 1");
  const int S = static_cast<int>(energy.size());
  std::vector<double> sigma(S);
  for (int s = 0; s < S; ++s) {
    double sum = 0;
    int pooled = 0;
    for (int n = std::max(s - 1, 0); n <= std::min(s + 1, S - 1); ++n, ++pooled) {
      if (!(energy[n] >= 0)) throw UsageError(fmt::format("segment {} has a negative rotor-rate energy", n));
      sum += energy[n];
    }
    sigma[s] = std::sqrt(sum / (static_cast<double>(pooled) * degree * controls));
  }
  return sigma;
}

void QuadrotorEstimateOptions::Validate() const {
  const OptionCheck check("QuadrotorEstimateOptions");
  const auto positive = [](double x) { return x > 0 && std::isfinite(x); };
  check(degree >= 2 && degree <= 64, "degree", "must be in [2, 64], got {}", degree);
  check(positive(segment_s), "segment_s", "must be a positive number of seconds, got {}", segment_s);
  check(positive(sigma_position_rate), "sigma_position_rate", "must be > 0, got {}", sigma_position_rate);
  check(positive(sigma_acceleration), "sigma_acceleration", "must be > 0, got {}", sigma_acceleration);
  check(positive(sigma_angular_acceleration), "sigma_angular_acceleration", "must be > 0, got {}",
        sigma_angular_acceleration);
  check(positive(sigma_rotation_rate), "sigma_rotation_rate", "must be > 0, got {}", sigma_rotation_rate);
  check(positive(sigma_rotor_rate), "sigma_rotor_rate", "must be > 0, got {}", sigma_rotor_rate);
  check(pilot_iterations >= 1, "pilot_iterations", "must be >= 1, got {}", pilot_iterations);
  check(positive(rotor_prior_sigma_floor), "rotor_prior_sigma_floor", "must be > 0, got {}",
        rotor_prior_sigma_floor);
  check(positive(thrust_prior_max_rate), "thrust_prior_max_rate", "must be > 0, got {}", thrust_prior_max_rate);
  check(positive(huber_pixels), "huber_pixels", "must be > 0, got {}", huber_pixels);
  check(positive(initial_window_s), "initial_window_s", "must be > 0, got {}", initial_window_s);
  check(positive(initial_trust_region_radius), "initial_trust_region_radius", "must be > 0, got {}",
        initial_trust_region_radius);
  check(max_iterations >= 1, "max_iterations", "must be >= 1, got {}", max_iterations);
  check(positive(function_tolerance), "function_tolerance", "must be > 0, got {}", function_tolerance);
  check(positive(gradient_tolerance), "gradient_tolerance", "must be > 0, got {}", gradient_tolerance);
  check(positive(parameter_tolerance), "parameter_tolerance", "must be > 0, got {}", parameter_tolerance);
  check(threads >= 1, "threads", "must be >= 1, got {}", threads);
}

namespace {

// The rotor speeds' components the rotor prior acts on: the collective and the roll, pitch and yaw
// combinations (the mixer's rows, orthonormal columns), so that with one σ for all four it is the
// per-rotor prior.
Eigen::Matrix4d RotorBasis() {
  Eigen::Matrix4d basis;
  basis << 1, 1, -1, -1,  //
      1, 1, 1, 1,         //
      1, -1, 1, -1,       //
      1, -1, -1, 1;
  return 0.5 * basis;  // columns: collective, roll, pitch, yaw
}

// The measurement interval [t0, t1]; ComputeError for a landmark id outside the map, fewer than two
// frame times or initial poses that do not cover the interval.
std::pair<double, double> MeasurementSpan(const std::vector<Eigen::Vector3d>& landmarks,
                                          const std::vector<PixelObservation>& pixels,
                                          const std::vector<PoseSample>& initial) {
  if (pixels.empty()) throw ComputeError("no camera measurements");
  double t0 = pixels.front().t, t1 = pixels.front().t;
  for (const PixelObservation& m : pixels) {
    t0 = std::min(t0, m.t);
    t1 = std::max(t1, m.t);
    if (m.landmark < 0 || m.landmark >= static_cast<int>(landmarks.size())) {
      throw ComputeError(fmt::format("measurement at {:.6f} s refers to landmark {}, but the map has {}", m.t, m.landmark,
                                     landmarks.size()));
    }
  }
  if (!(t1 > t0)) throw ComputeError("the camera measurements span no time (need frames at 2 or more times)");
  if (initial.empty() || initial.front().t > t0 + 1e-6 || initial.back().t < t1 - 1e-6) {
    throw ComputeError(fmt::format("the initial poses ({:.6f} .. {:.6f} s) do not cover the measurement interval "
                                   "[{:.6f}, {:.6f}] s",
                                   initial.empty() ? 0.0 : initial.front().t, initial.empty() ? 0.0 : initial.back().t,
                                   t0, t1));
  }
  return {t0, t1};
}

// round((t1 − t0) / segment_s) equal segments (at least one).
std::vector<double> Breakpoints(double t0, double t1, double segment_s, int degree) {
  const int segments = SegmentCount("QuadrotorEstimateOptions", t1 - t0, segment_s, degree);
  std::vector<double> breakpoints(segments + 1);
  for (int s = 0; s <= segments; ++s) breakpoints[s] = t0 + (t1 - t0) * s / segments;
  breakpoints.back() = t1;
  return breakpoints;
}

// Initial values: the flatness-based fit of the front end's poses (FlatnessInitialState) at every
// node; then the chart references.
void SetInitialValues(Problem& problem, const QuadrotorParameters& vehicle, const std::vector<PoseSample>& initial,
                      double window_s) {
  for (int g = 0; g < problem.num_nodes(); ++g) {
    const QuadrotorStateEstimate x0 = FlatnessInitialState(vehicle, initial, problem.NodeTime(g), window_s);
    Eigen::VectorXd x(9);
    x << x0.p, x0.v, x0.w;
    problem.SetNode(g, x, x0.R, x0.rotor);
  }
  problem.SetChartReferences();
}

Eigen::Matrix<double, 12, 1> CollocationSigma(const QuadrotorEstimateOptions& o) {
  Eigen::Matrix<double, 12, 1> sigma;
  sigma << Eigen::Vector3d::Constant(o.sigma_position_rate), Eigen::Vector3d::Constant(o.sigma_acceleration),
      Eigen::Vector3d::Constant(o.sigma_angular_acceleration), Eigen::Vector3d::Constant(o.sigma_rotation_rate);
  return sigma;
}

// One measurement per frame time: the pixels of all its landmarks, Huber per landmark.
void AddCameraMeasurements(Problem& problem, const PinholeCamera& cam, const std::vector<Eigen::Vector3d>& landmarks,
                           const std::vector<PixelObservation>& pixels, const ceres::LossFunction* huber) {
  const double pixel_sigma = std::max(cam.pixel_noise_px, 0.1);  // a noise-free file still gets a finite weight
  for (size_t i = 0; i < pixels.size();) {
    FrameProjection frame{PinholeCamera::BodyFromCamera().transpose(), cam.fx, cam.fy, cam.cx, cam.cy, 1.0 / pixel_sigma,
                          {}, {}};
    size_t j = i;
    for (; j < pixels.size() && pixels[j].t == pixels[i].t; ++j) {
      frame.points.push_back(landmarks[pixels[j].landmark]);
      frame.pixels.push_back(pixels[j].uv);
    }
    const int rows = static_cast<int>(2 * (j - i));
    problem.AddMeasurement(pixels[i].t, std::move(frame), rows, 2, {0}, huber);
    i = j;
  }
}

// Progress after every iteration of every solve (the pilot's and the final one's).
class IterationProgress : public ceres::IterationCallback {
 public:
  explicit IterationProgress(const ProgressFn& progress) : progress_(progress) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (summary.iteration > 0) ReportProgress(progress_, "solver iterations", ++done_, 0);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const ProgressFn& progress_;
  int64_t done_ = 0;
};

ceres::Solver::Options SolverOptions(const QuadrotorEstimateOptions& options, IterationProgress* progress) {
  ceres::Solver::Options solver;
  if (options.progress) solver.callbacks.push_back(progress);
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = options.threads;
  solver.logging_type = ceres::SILENT;
  solver.initial_trust_region_radius = options.initial_trust_region_radius;
  solver.function_tolerance = options.function_tolerance;
  solver.gradient_tolerance = options.gradient_tolerance;
  solver.parameter_tolerance = options.parameter_tolerance;
  return solver;
}

// Empirical Bayes after the pilot: σ_s = max(floor, AdaptiveRotorPriorSigma) per segment from the
// pilot's rotor rates; with thrust_prior the collective's rotor prior is replaced by the prior on
// the thrust acceleration (thrust_acceleration_prior.h), else all four components keep σ_s.
void SetPriorsFromPilot(Problem& problem, const QuadrotorParameters& vehicle, const QuadrotorEstimateOptions& options) {
  const int S = problem.num_segments();
  std::vector<double> energy(S);
  for (int s = 0; s < S; ++s) energy[s] = problem.ControlDerivativeEnergy(1, s);
  std::vector<double> sigma = AdaptiveRotorPriorSigma(energy, options.degree, QuadrotorModel::kControlDim);
  for (double& x : sigma) x = std::max(options.rotor_prior_sigma_floor, x);
  Problem::ControlBasis basis = RotorBasis();
  if (options.thrust_prior) {
    problem.RemoveControlSmoothnessPrior(1);
    basis = RotorBasis().rightCols<3>();  // the differential components
    problem.AddControlSmoothnessPrior(1, options.sigma_rotor_rate, basis);
    AddThrustAccelerationPrior(problem, vehicle, options.thrust_prior_max_rate);
  }
  for (int s = 0; s < S; ++s) problem.SetControlSmoothnessSigmas(1, s, Eigen::VectorXd::Constant(basis.cols(), sigma[s]));
}

QuadrotorEstimate Result(const Problem& problem, const ceres::Solver::Summary& summary, int iterations,
                         const std::vector<double>& query_times) {
  QuadrotorEstimate out;
  out.states = problem.num_nodes();
  out.segments = problem.num_segments();
  out.degree = problem.degree();
  out.iterations = iterations;
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.solver_report = summary.BriefReport();
  out.solver_full_report = summary.FullReport();
  out.start_time = problem.start_time();
  out.end_time = problem.end_time();
  for (double t : query_times) {
    if (t < out.start_time || t > out.end_time) continue;
    const StateSample s = problem.Interpolate(t);
    out.samples.push_back({t, s.vector.segment<3>(0), s.vector.segment<3>(3), s.vector.segment<3>(6), s.rotation,
                           s.control.head<4>()});
  }
  return out;
}

}  // namespace

QuadrotorEstimate EstimateQuadrotor(const Vehicle& vehicle, const std::vector<Eigen::Vector3d>& landmarks,
                                    const std::vector<PixelObservation>& pixels,
                                    const std::vector<PoseSample>& initial, const QuadrotorEstimateOptions& options,
                                    const std::vector<double>& query_times) {
  const auto start = std::chrono::steady_clock::now();
  options.Validate();
  const auto [t0, t1] = MeasurementSpan(landmarks, pixels, initial);
  Problem problem(QuadrotorModel{vehicle.quadrotor}, Breakpoints(t0, t1, options.segment_s, options.degree),
                  options.degree);
  SetInitialValues(problem, vehicle.quadrotor, initial, options.initial_window_s);
  problem.AddCollocation(CollocationSigma(options));
  problem.AddControlSmoothnessPrior(1, options.sigma_rotor_rate, RotorBasis());
  const ceres::HuberLoss huber(options.huber_pixels);
  AddCameraMeasurements(problem, vehicle.camera, landmarks, pixels, &huber);

  IterationProgress progress(options.progress);
  ceres::Solver::Options solver = SolverOptions(options, &progress);
  // 1. The pilot: a few iterations with the rotor prior at sigma_rotor_rate everywhere.
  solver.max_num_iterations = options.pilot_iterations;
  ceres::Solver::Summary summary = problem.Solve(solver);
  int iterations = static_cast<int>(summary.iterations.size()) - 1;
  // 2. σ per segment (and the thrust prior) from the pilot's solution.
  SetPriorsFromPilot(problem, vehicle.quadrotor, options);
  // 3. The solve to convergence.
  solver.max_num_iterations = options.max_iterations;
  summary = problem.Solve(solver);
  iterations += static_cast<int>(summary.iterations.size()) - 1;

  QuadrotorEstimate out = Result(problem, summary, iterations, query_times);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace cheval::estim
