// rpg_trajectory_evaluation's association, alignment and errors (see cheval/table/rpg.h; the Python
// function each piece follows is named in its comment).
#include "cheval/table/rpg.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <tuple>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "cheval/common/error.h"

namespace cheval::table {
namespace {

constexpr double kEps = 4.0 * 2.220446049250313e-16;  // transformations._EPS

// align_trajectory.get_best_yaw: the θ maximising trace(Rz(θ) C).
double BestYaw(const Eigen::Matrix3d& c) {
  const double a = c(0, 1) - c(1, 0);
  const double b = c(0, 0) + c(1, 1);
  return std::numbers::pi / 2 - std::atan2(b, a);
}

Eigen::Matrix3d RotZ(double theta) {
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  r(0, 0) = std::cos(theta);
  r(0, 1) = -std::sin(theta);
  r(1, 0) = std::sin(theta);
  r(1, 1) = std::cos(theta);
  return r;
}

// align_trajectory.align_umeyama(model = gt, data = est).
RpgAlignment Umeyama(const Eigen::Matrix3Xd& est, const Eigen::Matrix3Xd& gt, bool known_scale, bool yaw_only) {
  const double n = static_cast<double>(est.cols());
  const Eigen::Vector3d mu_m = gt.rowwise().mean(), mu_d = est.rowwise().mean();
  const Eigen::Matrix3Xd m = gt.colwise() - mu_m, d = est.colwise() - mu_d;
  RpgAlignment a;
  if (yaw_only) {
    a.R = RotZ(BestYaw(d * m.transpose()));
  } else {
    const Eigen::Matrix3d c = (m * d.transpose()) / n;
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(c, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d s = Eigen::Matrix3d::Identity();
    if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) s(2, 2) = -1;
    a.R = svd.matrixU() * s * svd.matrixV().transpose();
    if (!known_scale) {
      const double sigma2 = d.squaredNorm() / n;
      a.s = (svd.singularValues().asDiagonal() * s).trace() / sigma2;
    }
  }
  a.t = mu_m - a.s * a.R * mu_d;
  return a;
}

// transformations.logmap_so3, its norm (radians).
double LogmapAngle(const Eigen::Matrix3d& r) {
  const double tr = r.trace();
  Eigen::Vector3d omega;
  if (std::abs(tr + 1.0) < 1e-10) {
    if (std::abs(r(2, 2) + 1.0) > 1e-10) {
      omega = (std::numbers::pi / std::sqrt(2.0 + 2.0 * r(2, 2))) * Eigen::Vector3d(r(0, 2), r(1, 2), 1.0 + r(2, 2));
    } else if (std::abs(r(1, 1) + 1.0) > 1e-10) {
      omega = (std::numbers::pi / std::sqrt(2.0 + 2.0 * r(1, 1))) * Eigen::Vector3d(r(0, 1), 1.0 + r(1, 1), r(2, 1));
    } else {
      omega = (std::numbers::pi / std::sqrt(2.0 + 2.0 * r(0, 0))) * Eigen::Vector3d(1.0 + r(0, 0), r(1, 0), r(2, 0));
    }
  } else {
    const double tr_3 = tr - 3.0;
    double magnitude;
    if (tr_3 < -1e-7) {
      const double theta = std::acos((tr - 1.0) / 2.0);
      magnitude = theta / (2.0 * std::sin(theta));
    } else {
      magnitude = 0.5 - tr_3 * tr_3 / 12.0;
    }
    omega = magnitude * Eigen::Vector3d(r(2, 1) - r(1, 2), r(0, 2) - r(2, 0), r(1, 0) - r(0, 1));
  }
  return omega.norm();
}

double RadToDeg(double rad) { return rad * 180.0 / std::numbers::pi; }

// trajectory_utils.get_distance_from_start.
std::vector<double> DistanceFromStart(const Eigen::Matrix3Xd& p) {
  std::vector<double> d(static_cast<size_t>(p.cols()), 0.0);
  for (Eigen::Index i = 1; i < p.cols(); ++i) {
    d[static_cast<size_t>(i)] = d[static_cast<size_t>(i - 1)] + (p.col(i) - p.col(i - 1)).norm();
  }
  return d;
}

// trajectory_utils.compute_comparison_indices_length: for each start, the first index whose
// distance is strictly nearest d + dist within max_dist_diff; the list keeps only the found ones
// (rpg then pairs the k-th found one with start k, which this reproduces).
std::vector<Eigen::Index> ComparisonIndices(const std::vector<double>& distances, double dist, double max_dist_diff) {
  std::vector<Eigen::Index> comparisons;
  const size_t n = distances.size();
  for (size_t idx = 0; idx < n; ++idx) {
    const double target = distances[idx] + dist;
    // distances are non-decreasing, so distances[i] - target is too: skip those below the window.
    size_t i = static_cast<size_t>(
        std::partition_point(distances.begin() + static_cast<std::ptrdiff_t>(idx), distances.end(),
                             [&](double v) { return !(v - target > -max_dist_diff); }) -
        distances.begin());
    Eigen::Index best = -1;
    double error = max_dist_diff;
    for (; i < n; ++i) {
      const double x = distances[i] - target;
      if (std::abs(x) < error) {
        best = static_cast<Eigen::Index>(i);
        error = std::abs(x);
      } else if (x >= error) {
        break;  // later distances only grow
      }
    }
    if (best != -1) comparisons.push_back(best);
  }
  return comparisons;
}

}  // namespace

Eigen::Matrix3d RpgQuaternionMatrix(const Eigen::Vector4d& xyzw) {
  Eigen::Vector4d q = xyzw;
  const double nq = q.dot(q);
  if (nq < kEps) return Eigen::Matrix3d::Identity();
  q *= std::sqrt(2.0 / nq);
  const Eigen::Matrix4d o = q * q.transpose();
  Eigen::Matrix3d r;
  r << 1.0 - o(1, 1) - o(2, 2), o(0, 1) - o(2, 3), o(0, 2) + o(1, 3),  //
      o(0, 1) + o(2, 3), 1.0 - o(0, 0) - o(2, 2), o(1, 2) - o(0, 3),    //
      o(0, 2) - o(1, 3), o(1, 2) + o(0, 3), 1.0 - o(0, 0) - o(1, 1);
  return r;
}

std::vector<std::pair<Eigen::Index, Eigen::Index>> RpgAssociate(const std::vector<double>& est_t,
                                                                const std::vector<double>& gt_t, double max_diff) {
  std::vector<Eigen::Index> order(gt_t.size());
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::stable_sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) {
    return gt_t[static_cast<size_t>(a)] < gt_t[static_cast<size_t>(b)];
  });
  std::vector<std::tuple<double, Eigen::Index, Eigen::Index>> candidates;
  for (size_t i = 0; i < est_t.size(); ++i) {
    const double a = est_t[i];
    // A slightly wider window than max_diff found by binary search, then rpg's exact test.
    const double margin = 2 * max_diff + 1e-6 * std::abs(a);
    auto it = std::lower_bound(order.begin(), order.end(), a - margin,
                               [&](Eigen::Index j, double v) { return gt_t[static_cast<size_t>(j)] < v; });
    for (; it != order.end() && gt_t[static_cast<size_t>(*it)] <= a + margin; ++it) {
      const double diff = std::abs(a - gt_t[static_cast<size_t>(*it)]);
      if (diff < max_diff) candidates.emplace_back(diff, static_cast<Eigen::Index>(i), *it);
    }
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<char> est_used(est_t.size(), 0), gt_used(gt_t.size(), 0);
  std::vector<std::pair<Eigen::Index, Eigen::Index>> matches;
  for (const auto& [diff, i, j] : candidates) {
    if (est_used[static_cast<size_t>(i)] || gt_used[static_cast<size_t>(j)]) continue;
    est_used[static_cast<size_t>(i)] = gt_used[static_cast<size_t>(j)] = 1;
    matches.emplace_back(i, j);
  }
  std::sort(matches.begin(), matches.end());
  return matches;
}

RpgAlignment RpgAlign(const Eigen::Matrix3Xd& p_es, const Eigen::Matrix3Xd& p_gt, const Eigen::Matrix4Xd& q_es,
                      const Eigen::Matrix4Xd& q_gt, const std::string& type, int num_frames) {
  const Eigen::Index n_all = p_es.cols();
  if (n_all < 1) throw ComputeError("rpg alignment: no matched poses");
  if (type == "none") return {};
  if (num_frames != -1 && (num_frames < 1 || num_frames > n_all)) {
    throw ComputeError(fmt::format("rpg alignment: align_num_frames must be -1 or 1..{} (the matched poses), got {}",
                                   n_all, num_frames));
  }
  const Eigen::Index n = num_frames == -1 ? n_all : num_frames;
  const Eigen::Matrix3Xd est = p_es.leftCols(n), gt = p_gt.leftCols(n);
  if (type == "sim3") {
    if (num_frames == 1) throw ComputeError("rpg alignment: sim3 uses at least 2 frames (align_num_frames)");
    return Umeyama(est, gt, false, false);
  }
  if (type != "se3" && type != "posyaw") {
    throw ComputeError(fmt::format("rpg alignment: unknown align_type '{}'", type));
  }
  if (num_frames == 1) {  // alignPositionYawSingle / alignSE3Single: from the first poses' orientations
    const Eigen::Matrix3d g_rot = RpgQuaternionMatrix(q_gt.col(0)), est_rot = RpgQuaternionMatrix(q_es.col(0));
    RpgAlignment a;
    a.R = type == "se3" ? Eigen::Matrix3d(g_rot * est_rot.transpose()) : RotZ(BestYaw(est_rot * g_rot.transpose()));
    a.t = p_gt.col(0) - a.R * p_es.col(0);
    return a;
  }
  return Umeyama(est, gt, true, type == "posyaw");
}

double RpgRmse(const std::vector<double>& e) {
  if (e.empty()) return std::nan("");
  double sum = 0;
  for (double v : e) sum += v * v;
  return std::sqrt(sum / static_cast<double>(e.size()));
}

RpgResult RpgEvaluate(const RpgPoses& gt, const RpgPoses& est, const RpgEvalConfig& config,
                      const std::vector<double>& percentages) {
  // trajectory_loading.load_estimate_and_associate: pairs in estimate order, ground truth outside
  // start/end time dropped.
  std::vector<std::pair<Eigen::Index, Eigen::Index>> pairs;
  for (const auto& m : RpgAssociate(est.t, gt.t)) {
    const double t = gt.t[static_cast<size_t>(m.second)];
    if (t < config.start_time_s || t > config.end_time_s) continue;
    pairs.push_back(m);
  }
  const auto n = static_cast<Eigen::Index>(pairs.size());
  if (n == 0) throw ComputeError("rpg: no estimate stamp within 0.02 s of a ground-truth stamp");
  Eigen::Matrix3Xd p_es(3, n), p_gt(3, n);
  Eigen::Matrix4Xd q_es(4, n), q_gt(4, n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto [i, j] = pairs[static_cast<size_t>(k)];
    p_es.col(k) = est.p.col(i);
    q_es.col(k) = est.q.col(i);
    p_gt.col(k) = gt.p.col(j);
    q_gt.col(k) = gt.q.col(j);
  }
  RpgResult r;
  r.matched = n;
  r.alignment = RpgAlign(p_es, p_gt, q_es, q_gt, config.align_type, config.align_num_frames);
  const RpgAlignment& a = r.alignment;

  // compute_trajectory_errors.compute_absolute_error on the aligned estimate.
  std::vector<Eigen::Matrix3d> r_es(static_cast<size_t>(n)), r_gt(static_cast<size_t>(n));
  for (Eigen::Index k = 0; k < n; ++k) {
    r_es[static_cast<size_t>(k)] = RpgQuaternionMatrix(q_es.col(k));
    r_gt[static_cast<size_t>(k)] = RpgQuaternionMatrix(q_gt.col(k));
    const Eigen::Vector3d p_aligned = a.s * (a.R * p_es.col(k)) + a.t;
    r.abs_trans_m.push_back((p_gt.col(k) - p_aligned).norm());
    const Eigen::Matrix3d e_r = (a.R * r_es[static_cast<size_t>(k)]) * r_gt[static_cast<size_t>(k)].inverse();
    r.abs_rot_deg.push_back(RadToDeg(LogmapAngle(e_r)));
  }
  r.rmse_trans_m = RpgRmse(r.abs_trans_m);
  r.rmse_rot_deg = RpgRmse(r.abs_rot_deg);

  // Trajectory.compute_boxplot_distances: the raw ground truth's length (inside start/end time),
  // each percentage of it truncated to 2 decimals.
  Eigen::Matrix3Xd raw(3, gt.size());
  Eigen::Index m = 0;
  for (Eigen::Index j = 0; j < gt.size(); ++j) {
    const double t = gt.t[static_cast<size_t>(j)];
    if (t < config.start_time_s || t > config.end_time_s) continue;
    raw.col(m++) = gt.p.col(j);
  }
  r.gt_length_m = m > 0 ? DistanceFromStart(raw.leftCols(m)).back() : 0.0;
  const std::vector<double> accum = DistanceFromStart(p_gt);
  for (double pct : percentages) {
    RpgRelativeErrors rel;
    rel.distance_m = std::trunc(pct * r.gt_length_m * 100.0) / 100.0;
    const std::vector<Eigen::Index> comparisons = ComparisonIndices(accum, rel.distance_m, 0.2 * rel.distance_m);
    if (comparisons.size() >= 2) {
      for (size_t idx = 0; idx < comparisons.size(); ++idx) {
        const auto i = static_cast<Eigen::Index>(idx), c = comparisons[idx];
        const Eigen::Matrix3d& rc1 = r_es[static_cast<size_t>(i)];
        const Eigen::Matrix3d& rc2 = r_es[static_cast<size_t>(c)];
        const Eigen::Matrix3d& rm1 = r_gt[static_cast<size_t>(i)];
        const Eigen::Matrix3d& rm2 = r_gt[static_cast<size_t>(c)];
        const Eigen::Matrix3d r_c = rc1.transpose() * rc2;
        const Eigen::Vector3d t_c = a.s * (rc1.transpose() * (p_es.col(c) - p_es.col(i)));
        const Eigen::Matrix3d r_m = rm1.transpose() * rm2;
        const Eigen::Vector3d t_m = rm1.transpose() * (p_gt.col(c) - p_gt.col(i));
        const Eigen::Matrix3d r_e = r_m.transpose() * r_c;
        const Eigen::Vector3d t_e = r_m.transpose() * (t_c - t_m);
        const Eigen::Matrix3d r_w = rc2 * r_e * rc2.transpose();
        const double tn = (rc2 * t_e).norm();
        rel.trans_m.push_back(tn);
        rel.trans_percent.push_back(tn / rel.distance_m * 100);
        rel.rot_deg.push_back(RadToDeg(std::acos(std::min(1.0, std::max(-1.0, (r_w.trace() - 1) / 2)))));
      }
    }
    r.relative.push_back(std::move(rel));
  }
  return r;
}

}  // namespace cheval::table
