#include "cheval/estim/quadrotor_estimator.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <Eigen/Dense>

#include "cheval/common/error.h"
#include "cheval/estim/problem.h"
#include "cheval/lie/so3.h"

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


// Rows w (Σ_k C_a(q, k) f_k[a] + o(q, a)) (axis a = x, y, z) of the thrust acceleration
// f_k = (k_F/m) Σ_i Ω_ik² R_k e3 (world frame) of the given nodes: with C_a the smoothness rows of a
// segment, ∫ |f^(m)|² dt / σ² of the polynomial through the nodes' f (a white-noise prior on the m-th
// derivative of the thrust vector); with C_a = rows of D² + ω_a² and o = −ω² ḡ, ∫ |f'' + ω²(f − ḡ)|².
class ThrustVectorSmoothnessCost : public ceres::CostFunction {
 public:
  ThrustVectorSmoothnessCost(Problem& p, const std::vector<int>& nodes, std::array<Eigen::MatrixXd, 3> coefficients,
                             Eigen::MatrixXd offsets, double k_over_m)
      : coefficients_(std::move(coefficients)), offsets_(std::move(offsets)), k_over_m_(k_over_m) {
    for (int g : nodes) {
      blocks_.push_back(p.Control(g));
      blocks_.push_back(p.Quaternion(g));
      mutable_parameter_block_sizes()->push_back(4);
      mutable_parameter_block_sizes()->push_back(4);
    }
    if (offsets_.size() == 0) offsets_ = Eigen::MatrixXd::Zero(coefficients_[0].rows(), 3);
    set_num_residuals(3 * static_cast<int>(coefficients_[0].rows()));
  }
  ThrustVectorSmoothnessCost(Problem& p, const std::vector<int>& nodes, const Eigen::MatrixXd& coefficients, double k_over_m)
      : ThrustVectorSmoothnessCost(p, nodes, {coefficients, coefficients, coefficients}, Eigen::MatrixXd(), k_over_m) {}
  const std::vector<double*>& blocks() const { return blocks_; }
  void set_weight(double w) { weight_ = w; }
  void set_rows(std::array<Eigen::MatrixXd, 3> coefficients, Eigen::MatrixXd offsets) {
    coefficients_ = std::move(coefficients);
    offsets_ = std::move(offsets);
  }
  static Eigen::Vector3d ThrustAcceleration(const double* u, const double* q, double k_over_m) {
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    const Eigen::Vector3d b3(2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y));
    return k_over_m * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2] + u[3] * u[3]) * b3;
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const int rows = static_cast<int>(coefficients_[0].rows()), nodes = static_cast<int>(coefficients_[0].cols());
    Eigen::Map<Eigen::VectorXd> r(residuals, 3 * rows);
    for (int row = 0; row < rows; ++row) r.segment<3>(3 * row) = weight_ * offsets_.row(row).transpose();
    for (int k = 0; k < nodes; ++k) {
      const double* u = parameters[2 * k];
      const double* q = parameters[2 * k + 1];
      const Eigen::Vector3d f = ThrustAcceleration(u, q, k_over_m_);
      for (int row = 0; row < rows; ++row) {
        for (int a = 0; a < 3; ++a) r[3 * row + a] += weight_ * coefficients_[a](row, k) * f[a];
      }
      if (!jacobians) continue;
      const double x = q[0], y = q[1], z = q[2], w = q[3];
      const double t = k_over_m_ * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2] + u[3] * u[3]);
      const Eigen::Vector3d b3(2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y));
      Eigen::Matrix<double, 3, 4> df_du = (2 * k_over_m_) * b3 * Eigen::Map<const Eigen::RowVector4d>(u);
      Eigen::Matrix<double, 3, 4> df_dq;
      df_dq.col(0) = Eigen::Vector3d(2 * z, -2 * w, -4 * x);
      df_dq.col(1) = Eigen::Vector3d(2 * w, 2 * z, -4 * y);
      df_dq.col(2) = Eigen::Vector3d(2 * x, 2 * y, 0);
      df_dq.col(3) = Eigen::Vector3d(2 * y, -2 * x, 0);
      df_dq *= t;
      for (int b = 0; b < 2; ++b) {
        if (!jacobians[2 * k + b]) continue;
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>> J(jacobians[2 * k + b], 3 * rows, 4);
        const Eigen::Matrix<double, 3, 4>& df = b == 0 ? df_du : df_dq;
        for (int row = 0; row < rows; ++row) {
          for (int a = 0; a < 3; ++a) J.row(3 * row + a) = weight_ * coefficients_[a](row, k) * df.row(a);
        }
      }
    }
    return true;
  }

 private:
  std::vector<double*> blocks_;
  std::array<Eigen::MatrixXd, 3> coefficients_;
  Eigen::MatrixXd offsets_;
  double k_over_m_;
  double weight_ = 1.0;
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

QuadrotorEstimate EstimateQuadrotor(const Vehicle& vehicle, const std::vector<Eigen::Vector3d>& landmarks,
                                    const std::vector<PixelObservation>& pixels,
                                    const std::vector<PoseSample>& initial, const QuadrotorEstimateOptions& options,
                                    const std::vector<double>& query_times) {
  const auto start = std::chrono::steady_clock::now();
  if (options.degree < 2 || options.degree > 64) throw UsageError(fmt::format("--degree must be in [2, 64], got {}", options.degree));
  if (!(options.segment_s > 0) || !std::isfinite(options.segment_s)) {
    throw UsageError(fmt::format("--segment must be a positive number of seconds, got {}", options.segment_s));
  }
  if (options.pilot_iterations < 1) {
    throw UsageError(fmt::format("the pilot solve needs >= 1 iteration, got {}", options.pilot_iterations));
  }
  if (!(options.adaptive_rotor_prior_floor > 0)) {
    throw UsageError(fmt::format("the adaptive rotor-prior floor must be > 0, got {}", options.adaptive_rotor_prior_floor));
  }
  if (!(options.initial_trust_region_radius > 0)) {
    throw UsageError(fmt::format("the initial trust-region radius must be > 0, got {}", options.initial_trust_region_radius));
  }
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
  const int segments = std::max(1, static_cast<int>(std::lround((t1 - t0) / options.segment_s)));
  std::vector<double> breakpoints(segments + 1);
  for (int s = 0; s <= segments; ++s) breakpoints[s] = t0 + (t1 - t0) * s / segments;
  breakpoints.back() = t1;
  Problem problem(QuadrotorModel{vehicle.quadrotor}, breakpoints, options.degree);

  // Initial values: the flatness-based fit of the front end's poses (FlatnessInitialState).
  for (int g = 0; g < problem.num_nodes(); ++g) {
    const QuadrotorStateEstimate x0 = FlatnessInitialState(vehicle.quadrotor, initial, problem.NodeTime(g),
                                                           options.initial_window_s);
    Eigen::VectorXd x(9);
    x << x0.p, x0.v, x0.w;
    problem.SetNode(g, x, x0.R, x0.rotor);
  }
  problem.SetChartReferences();

  Eigen::Matrix<double, 12, 1> sigma;
  sigma << Eigen::Vector3d::Constant(options.sigma_position_rate), Eigen::Vector3d::Constant(options.sigma_acceleration),
      Eigen::Vector3d::Constant(options.sigma_angular_acceleration), Eigen::Vector3d::Constant(options.sigma_rotation_rate);
  problem.AddCollocation(sigma);
  Eigen::Matrix4d prior_basis = Eigen::Matrix4d::Identity();
  if (options.collective_split) {
    prior_basis << 1, 1, -1, -1,  //
        1, 1, 1, 1,               //
        1, -1, 1, -1,             //
        1, -1, -1, 1;
    prior_basis *= 0.5;
  }
  if (options.sigma_rotor_rate > 0) {
    problem.AddControlSmoothnessPrior(options.rotor_prior_order, options.sigma_rotor_rate, prior_basis);
  }
  if (options.sigma_rotor_acceleration > 0) problem.AddControlSmoothnessPrior(2, options.sigma_rotor_acceleration, prior_basis);
  // Experimental: the collective's prior on the world-frame thrust acceleration instead (weight 0 in the pilot).
  std::vector<ThrustVectorSmoothnessCost*> thrust_costs, thrust_jumps, start_costs;
  Eigen::Vector3d oscillator_lambda = Eigen::Vector3d::Zero();  // λ per axis of (D + λ)² (ζ = 1)
  std::vector<std::pair<std::array<Eigen::MatrixXd, 3>, Eigen::MatrixXd>> oscillator_rows;
  const double k_over_m = vehicle.quadrotor.thrust_coefficient / vehicle.quadrotor.mass_kg;
  if (options.thrust_vector_prior_order > 0) {
    const int m = options.thrust_vector_prior_order, N = options.degree;
    for (int s = 0; s < problem.num_segments(); ++s) {
      std::vector<int> nodes;
      for (int k = 0; k <= N; ++k) nodes.push_back(problem.NodeOf(s, k));
      auto* cost = new ThrustVectorSmoothnessCost(problem, nodes, problem.SmoothnessMatrix(m, s), k_over_m);
      cost->set_weight(std::getenv("CHEVAL_CHECK_GRADIENTS") ? 1.0 : 0.0);
      problem.ceres_problem().AddResidualBlock(cost, nullptr, cost->blocks());
      thrust_costs.push_back(cost);
    }
    for (int s = 0; m > 1 && options.thrust_vector_jumps && s + 1 < problem.num_segments(); ++s) {
      std::vector<int> nodes;
      for (int g = s * N; g <= (s + 2) * N; ++g) nodes.push_back(g);
      auto* cost = new ThrustVectorSmoothnessCost(problem, nodes, problem.SmoothnessJumpMatrix(m, s, 1.0), k_over_m);
      cost->set_weight(std::getenv("CHEVAL_CHECK_GRADIENTS") ? 1.0 : 0.0);
      problem.ceres_problem().AddResidualBlock(cost, nullptr, cost->blocks());
      thrust_jumps.push_back(cost);
    }
  }

  const PinholeCamera& cam = vehicle.camera;
  const double pixel_sigma = std::max(cam.pixel_noise_px, 0.1);  // a noise-free file still gets a finite weight
  ceres::HuberLoss huber(options.huber_pixels);
  for (size_t i = 0; i < pixels.size();) {
    FrameProjection frame{PinholeCamera::BodyFromCamera().transpose(), cam.fx, cam.fy, cam.cx, cam.cy, 1.0 / pixel_sigma,
                          {}, {}};
    size_t j = i;
    for (; j < pixels.size() && pixels[j].t == pixels[i].t; ++j) {
      frame.points.push_back(landmarks[pixels[j].landmark]);
      frame.pixels.push_back(pixels[j].uv);
    }
    const int rows = static_cast<int>(2 * (j - i));
    problem.AddMeasurement(pixels[i].t, std::move(frame), rows, 2, {0}, &huber);
    i = j;
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
  } iteration_progress(options.progress);
  ceres::Solver::Options solver;
  if (options.progress) solver.callbacks.push_back(&iteration_progress);
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = options.threads;
  solver.logging_type = ceres::SILENT;
  solver.initial_trust_region_radius = options.initial_trust_region_radius;
  if (std::getenv("CHEVAL_CHECK_GRADIENTS")) solver.check_gradients = true;
  const bool adaptive = options.adaptive_rotor_prior && options.sigma_rotor_rate > 0 &&
                        (options.rotor_prior_order == 1 || options.rotor_prior_order == 2);
  if (adaptive) solver.max_num_iterations = options.pilot_iterations;
  ceres::Solver::Summary summary = problem.Solve(solver);
  int iterations = static_cast<int>(summary.iterations.size()) - 1;
  if (adaptive) {  // empirical Bayes: σ per segment from the pilot's rotor speeds, then the solve
    const int S = problem.num_segments(), N = options.degree;
    struct Prior {
      int order;
      double floor;
    };
    std::vector<Prior> priors{{options.rotor_prior_order, options.rotor_prior_order == 1 ? options.adaptive_rotor_prior_floor
                                                                                         : options.second_order_floor}};
    if (options.sigma_rotor_acceleration > 0) priors.push_back({2, options.second_order_floor});
    for (int em = 0; em < std::max(1, options.em_iterations); ++em) {
      // Posterior covariance of every segment's rotor blocks (the E-step's variance term).
      std::vector<Eigen::MatrixXd> cov;
      if (options.posterior_variance) {
        ceres::Covariance::Options co;
        co.num_threads = options.threads;
        co.algorithm_type = ceres::SPARSE_QR;
        ceres::Covariance covariance(co);
        std::vector<std::pair<const double*, const double*>> pairs;
        for (int s = 0; s < S; ++s) {
          for (int k = 0; k <= N; ++k) {
            for (int l = k; l <= N; ++l) {
              const int a = problem.NodeOf(s, k), b = problem.NodeOf(s, l);
              if (s > 0 && (k == N && l == N)) continue;  // the shared start node: already its predecessor's end
              pairs.emplace_back(problem.Control(std::min(a, b)), problem.Control(std::max(a, b)));
            }
          }
        }
        if (!covariance.Compute(pairs, &problem.ceres_problem())) throw ComputeError("the rotor covariance failed");
        for (int s = 0; s < S; ++s) {
          Eigen::MatrixXd C(4 * (N + 1), 4 * (N + 1));
          for (int k = 0; k <= N; ++k) {
            for (int l = k; l <= N; ++l) {
              const int a = problem.NodeOf(s, k), b = problem.NodeOf(s, l);
              Eigen::Matrix<double, 4, 4, Eigen::RowMajor> block;
              covariance.GetCovarianceBlock(problem.Control(a), problem.Control(b), block.data());
              C.block<4, 4>(4 * k, 4 * l) = block;
              C.block<4, 4>(4 * l, 4 * k) = block.transpose();
            }
          }
          cov.push_back(C);
        }
      }
      Eigen::Matrix4d basis = Eigen::Matrix4d::Identity();
      if (options.collective_split) {
        basis << 1, 1, -1, -1,  //
            1, 1, 1, 1,         //
            1, -1, 1, -1,       //
            1, -1, -1, 1;
        basis *= 0.5;  // columns: collective, roll, pitch, yaw (the mixer's rows: models.h)
      }
      for (const Prior& prior : priors) {
        std::vector<Eigen::Vector4d> energy(S);
        for (int s = 0; s < S; ++s) {
          energy[s] = problem.ControlDerivativeEnergies(prior.order, s, basis);
          if (options.posterior_variance) {
            const Eigen::MatrixXd M = problem.SmoothnessMatrix(prior.order, s);  // rows x N + 1
            for (int j = 0; j < 4; ++j) {
              Eigen::MatrixXd A(M.rows(), 4 * (N + 1));
              for (int q = 0; q < M.rows(); ++q) {
                for (int k = 0; k <= N; ++k) A.block(q, 4 * k, 1, 4) = M(q, k) * basis.col(j).transpose();
              }
              energy[s][j] += (A * cov[s] * A.transpose()).trace();
            }
          }
        }
        const double increments = N + 1 - prior.order;  // rank of one segment's prior per component
        for (int s = 0; s < S; ++s) {
          Eigen::Vector4d sum = Eigen::Vector4d::Zero();
          int pooled = 0;
          for (int n = std::max(s - 1, 0); n <= std::min(s + 1, S - 1); ++n, ++pooled) sum += energy[n];
          Eigen::Vector4d seg_sigma;
          if (options.collective_split) {
            seg_sigma = (sum / (pooled * increments)).cwiseSqrt();
          } else {
            seg_sigma.setConstant(std::sqrt(sum.sum() / (pooled * increments * 4)));
          }
          seg_sigma = (options.adaptive_scale * seg_sigma).cwiseMax(prior.floor);
          problem.SetControlSmoothnessSigmas(prior.order, s, seg_sigma);
          if (std::getenv("CHEVAL_DEBUG_SIGMA")) {
            std::fprintf(stderr, "em %d order %d segment %d sigma %.1f %.1f %.1f %.1f\n", em, prior.order, s, seg_sigma[0],
                         seg_sigma[1], seg_sigma[2], seg_sigma[3]);
          }
        }
      }
      // Posterior covariance of each segment's thrust accelerations f_k (3 (N + 1) square, node-major), by
      // linearising f in the controls and rotations: the E-step's variance term.
      std::vector<Eigen::MatrixXd> covf;
      if (options.thrust_em && em > 0 && !thrust_costs.empty()) {
        ceres::Covariance::Options co;
        co.num_threads = options.threads;
        co.algorithm_type = ceres::SPARSE_QR;
        ceres::Covariance covariance(co);
        std::vector<std::pair<const double*, const double*>> pairs;
        auto block = [&](int g, int b) -> const double* { return b == 0 ? problem.Control(g) : problem.Quaternion(g); };
        for (int s = 0; s < S; ++s) {
          for (int k = 0; k <= N; ++k) {
            for (int l = k; l <= N; ++l) {
              if (s > 0 && k == N && l == N) continue;
              for (int b = 0; b < 2; ++b) {
                for (int c = 0; c < 2; ++c) {
                  if (k == l && c < b) continue;
                  pairs.emplace_back(block(problem.NodeOf(s, k), b), block(problem.NodeOf(s, l), c));
                }
              }
            }
          }
        }
        if (!covariance.Compute(pairs, &problem.ceres_problem())) throw ComputeError("the thrust covariance failed");
        for (int s = 0; s < S; ++s) {
          Eigen::MatrixXd Sigma(7 * (N + 1), 7 * (N + 1));
          for (int k = 0; k <= N; ++k) {
            for (int l = k; l <= N; ++l) {
              for (int b = 0; b < 2; ++b) {
                for (int c = 0; c < 2; ++c) {
                  if (k == l && c < b) continue;
                  const int nb = b == 0 ? 4 : 3, nc = c == 0 ? 4 : 3;
                  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> B(nb, nc);
                  covariance.GetCovarianceBlockInTangentSpace(block(problem.NodeOf(s, k), b), block(problem.NodeOf(s, l), c), B.data());
                  Sigma.block(7 * k + 4 * b, 7 * l + 4 * c, nb, nc) = B;
                  Sigma.block(7 * l + 4 * c, 7 * k + 4 * b, nc, nb) = B.transpose();
                }
              }
            }
          }
          Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3 * (N + 1), 7 * (N + 1));
          Eigen::Matrix3d e3x;
          e3x << 0, -1, 0, 1, 0, 0, 0, 0, 0;
          for (int k = 0; k <= N; ++k) {
            const int g = problem.NodeOf(s, k);
            const Eigen::Map<const Eigen::Vector4d> u(problem.Control(g));
            const Eigen::Matrix3d R = Eigen::Quaterniond(Eigen::Map<const Eigen::Vector4d>(problem.Quaternion(g))).toRotationMatrix();
            J.block<3, 4>(3 * k, 7 * k) = (2 * k_over_m) * R.col(2) * u.transpose();
            J.block<3, 3>(3 * k, 7 * k + 4) = -k_over_m * u.squaredNorm() * R * e3x;
          }
          covf.push_back(J * Sigma * J.transpose());
        }
      }
      // tr(A Cov(F_a) Aᵀ) summed over the axes.
      auto variance = [&](int s, const std::array<Eigen::MatrixXd, 3>& A) {
        double v = 0;
        for (int a = 0; a < 3; ++a) {
          Eigen::MatrixXd Ca(N + 1, N + 1);
          for (int k = 0; k <= N; ++k) {
            for (int l = 0; l <= N; ++l) Ca(k, l) = covf[s](3 * k + a, 3 * l + a);
          }
          v += (A[a] * Ca * A[a].transpose()).trace();
        }
        return v;
      };
      if (options.thrust_oscillator && (em == 0 || (options.thrust_matern_ml && !covf.empty()))) {
        // ω_a² per axis: least squares of â'' = −ω² â over the pilot's thrust acceleration minus hover
        // (â = f − ḡ), at N + 1 Gauss–Legendre points per segment; clamped to [0, ω_max²].
        const Eigen::Vector3d gbar(0, 0, vehicle.quadrotor.gravity_mps2);
        Eigen::Vector3d num = Eigen::Vector3d::Zero(), den = Eigen::Vector3d::Zero();
        std::vector<Eigen::MatrixXd> F(S);
        std::vector<Eigen::MatrixXd> R0(S), R1(S), R2(S);
        for (int s = 0; s < S; ++s) {
          F[s].resize(N + 1, 3);
          for (int k = 0; k <= N; ++k) {
            const int g = problem.NodeOf(s, k);
            F[s].row(k) = (ThrustVectorSmoothnessCost::ThrustAcceleration(problem.Control(g), problem.Quaternion(g), k_over_m) - gbar).transpose();
          }
          R0[s] = problem.SmoothnessMatrix(0, s, N + 1);
          R1[s] = problem.SmoothnessMatrix(1, s, N + 1);
          R2[s] = problem.SmoothnessMatrix(2, s, N + 1);
          const Eigen::MatrixXd A0 = R0[s] * F[s], A2 = R2[s] * F[s];
          for (int a = 0; a < 3; ++a) {
            num[a] += -A2.col(a).dot(A0.col(a));
            den[a] += A0.col(a).squaredNorm();
          }
        }
        Eigen::Vector3d w2;
        for (int a = 0; a < 3; ++a) w2[a] = std::clamp(den[a] > 0 ? num[a] / den[a] : 0.0, 0.0, options.thrust_oscillator_max * options.thrust_oscillator_max);
        if (options.thrust_oscillator_isotropic) w2.setConstant(std::clamp(num.sum() / std::max(den.sum(), 1e-300), 0.0, options.thrust_oscillator_max * options.thrust_oscillator_max));
        if (options.thrust_matern > 0) w2.setConstant(options.thrust_matern * options.thrust_matern);
        if (options.thrust_matern_ml) {
          // Type-II maximum likelihood of λ for (D + λ)² (f − ḡ) = white noise with σ per segment
          // (profiled out): −log p = Σ_s (n_s/2) log E_s(λ) − λ T per axis + const (the λ part of
          // ½ log det L*L is λ T for L = (D + λ)²), n_s = 3 N; E_s the energy of the current estimate,
          // plus its posterior variance when there is one (EM).
          const double T = problem.end_time() - problem.start_time();
          double best = 0, best_nll = 1e300;
          for (int i = 0; i <= 80; ++i) {
            const double lambda = 0.1 * std::pow(100.0, i / 80.0);  // 0.1 .. 10 /s
            double nll = -3.0 * lambda * T;
            for (int s = 0; s < S; ++s) {
              const Eigen::MatrixXd A = R2[s] + 2 * lambda * R1[s] + lambda * lambda * R0[s];
              double e = (A * F[s]).squaredNorm();
              if (!covf.empty()) e += variance(s, {A, A, A});
              nll += 0.5 * 3.0 * N * std::log(e);
            }
            if (nll < best_nll) best_nll = nll, best = lambda;
          }
          w2.setConstant(best * best);
        }
        oscillator_lambda = (options.thrust_damping > 0 ? 1.0 : 0.0) * w2.cwiseSqrt();
        if (std::getenv("CHEVAL_DEBUG_SIGMA")) std::fprintf(stderr, "em %d omega %.3f %.3f %.3f\n", em, std::sqrt(w2[0]), std::sqrt(w2[1]), std::sqrt(w2[2]));
        if (oscillator_rows.empty()) {
          for (auto* c : thrust_costs) c->set_weight(0.0);  // replaced by the oscillator rows
          thrust_costs.clear();
        }
        for (int s = 0; s < S; ++s) {
          std::vector<int> nodes;
          for (int k = 0; k <= N; ++k) nodes.push_back(problem.NodeOf(s, k));
          std::array<Eigen::MatrixXd, 3> C;
          Eigen::MatrixXd offsets(N + 1, 3);
          for (int a = 0; a < 3; ++a) {
            C[a] = R2[s] + w2[a] * R0[s] + 2 * options.thrust_damping * std::sqrt(w2[a]) * R1[s];
            offsets.col(a) = -w2[a] * gbar[a] * R0[s].rowwise().sum();
          }
          if (static_cast<int>(oscillator_rows.size()) == S) {
            thrust_costs[s]->set_rows(C, offsets);
            oscillator_rows[s] = {C, offsets};
            continue;
          }
          auto* cost = new ThrustVectorSmoothnessCost(problem, nodes, C, offsets, k_over_m);
          problem.ceres_problem().AddResidualBlock(cost, nullptr, cost->blocks());
          thrust_costs.push_back(cost);
          oscillator_rows.push_back({C, offsets});
        }
      }
      if (!thrust_costs.empty()) {
        const int m = options.thrust_vector_prior_order;
        const double floor_f = options.adaptive_rotor_prior_floor * vehicle.quadrotor.gravity_mps2 /
                               vehicle.quadrotor.HoverRotorSpeed() * options.thrust_floor_factor;
        std::vector<double> energy(S);
        for (int s = 0; s < S; ++s) {
          const Eigen::MatrixXd M = problem.SmoothnessMatrix(m, s);
          Eigen::MatrixXd F(N + 1, 3);
          for (int k = 0; k <= N; ++k) {
            const int g = problem.NodeOf(s, k);
            F.row(k) = ThrustVectorSmoothnessCost::ThrustAcceleration(problem.Control(g), problem.Quaternion(g), k_over_m)
                           .transpose();
          }
          if (!oscillator_rows.empty()) {
            double e = 0;
            for (int a = 0; a < 3; ++a) e += (oscillator_rows[s].first[a] * F.col(a) + oscillator_rows[s].second.col(a)).squaredNorm();
            energy[s] = e;
            if (!covf.empty()) energy[s] += variance(s, oscillator_rows[s].first);
          } else {
            energy[s] = (M * F).squaredNorm();
            if (!covf.empty()) energy[s] += variance(s, {M, M, M});
          }
        }
        std::vector<double> sf(S);
        for (int s = 0; s < S; ++s) {
          double sum = 0;
          int pooled = 0;
          for (int n = std::max(s - options.thrust_pool, 0); n <= std::min(s + options.thrust_pool, S - 1); ++n, ++pooled) sum += energy[n];
          sf[s] = std::max(floor_f, options.adaptive_scale * options.thrust_scale * std::sqrt(sum / (pooled * 3.0 * (N + 1 - m))));
          thrust_costs[s]->set_weight(1.0 / sf[s]);
          if (std::getenv("CHEVAL_DEBUG_SIGMA")) std::fprintf(stderr, "thrust segment %d sigma %.3f floor %.3f\n", s, sf[s], floor_f);
        }
        for (size_t j = 0; j < thrust_jumps.size(); ++j) thrust_jumps[j]->set_weight(1.0 / std::sqrt(sf[j] * sf[j + 1]));
        if (options.thrust_stationary_start && oscillator_lambda.maxCoeff() > 0) {
          // The proper (stationary) Matérn prior's initial state: a(t0) ~ N(0, σ²/(4λ³)), a'(t0) ~ N(0, σ²/(4λ))
          // per axis, a = f − ḡ, σ the first segment's: with the forward energy of (D + λ)² a this is the
          // exact density of the stationary process (time-symmetric); thrust_stationary_both: at t1 too.
          const Eigen::Vector3d gbar(0, 0, vehicle.quadrotor.gravity_mps2);
          for (int end = 0; end < (options.thrust_stationary_both ? 2 : 1); ++end) {
            const int s = end == 0 ? 0 : S - 1;
            const double sig = sf[s];
            const detail::TimeRow row = problem.RowAt(end == 0 ? problem.start_time() : problem.end_time());
            std::array<Eigen::MatrixXd, 3> C;
            Eigen::MatrixXd offsets(2, 3);
            for (int a = 0; a < 3; ++a) {
              const double lambda = std::max(oscillator_lambda[a], 1e-3);
              const double sd0 = sig / std::sqrt(4 * lambda * lambda * lambda), sd1 = sig / std::sqrt(4 * lambda);
              C[a].resize(2, N + 1);
              C[a].row(0) = row.w / sd0;
              C[a].row(1) = row.dw / sd1;
              offsets(0, a) = -gbar[a] / sd0;
              offsets(1, a) = 0;
            }
            if (static_cast<int>(start_costs.size()) > end) {
              start_costs[end]->set_rows(C, offsets);
            } else {
              std::vector<int> nodes;
              for (int k = 0; k <= N; ++k) nodes.push_back(problem.NodeOf(s, k));
              auto* cost = new ThrustVectorSmoothnessCost(problem, nodes, C, offsets, k_over_m);
              problem.ceres_problem().AddResidualBlock(cost, nullptr, cost->blocks());
              start_costs.push_back(cost);
            }
          }
        }
        // The collective's rotor-speed prior off, the differential ones as before.
        for (int s = 0; s < S; ++s) {
          Eigen::Vector4d e = Eigen::Vector4d::Zero();
          int pooled = 0;
          for (int n = std::max(s - 1, 0); n <= std::min(s + 1, S - 1); ++n, ++pooled) e += problem.ControlDerivativeEnergies(1, n, basis);
          double sd = options.thrust_differential_own ? std::sqrt(e.tail<3>().sum() / (pooled * N * 3.0))
                                                     : std::sqrt(e.sum() / (pooled * N * 4.0));
          sd = std::max(options.adaptive_rotor_prior_floor, options.adaptive_scale * sd);
          problem.SetControlSmoothnessSigmas(1, s, Eigen::Vector4d(options.thrust_keep_collective > 0 ? options.thrust_keep_collective * sd : 1e9, sd, sd, sd));
        }
      }
      if (em + 1 < options.em_iterations) {
        solver.max_num_iterations = options.pilot_iterations;
        summary = problem.Solve(solver);
        iterations += static_cast<int>(summary.iterations.size()) - 1;
      }
    }
    solver.max_num_iterations = options.max_iterations;
    summary = problem.Solve(solver);
    iterations += static_cast<int>(summary.iterations.size()) - 1;
  }

  QuadrotorEstimate out;
  out.states = problem.num_nodes();
  out.segments = problem.num_segments();
  out.degree = problem.degree();
  out.iterations = iterations;
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.solver_report = summary.BriefReport();
  out.solver_full_report = summary.FullReport();
  out.start_time = t0;
  out.end_time = t1;
  for (double t : query_times) {
    if (t < t0 || t > t1) continue;
    const StateSample s = problem.Interpolate(t);
    out.samples.push_back({t, s.vector.segment<3>(0), s.vector.segment<3>(3), s.vector.segment<3>(6), s.rotation,
                           s.control.head<4>()});
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace cheval::estim
