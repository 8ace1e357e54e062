#include "cheval/eval/extrinsic.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include <Eigen/Geometry>
#include <fmt/format.h>

#include "cheval/common/error.h"
#include "cheval/common/input_file.h"
#include "cheval/common/npy.h"

namespace cheval::eval {
namespace {

constexpr double kOrthonormalTolerance = 1e-6;
constexpr uint64_t kMaxBytes = 1 << 20;  // a transform file is a few hundred bytes

[[noreturn]] void Fail(const std::string& path, int64_t line, const std::string& what) {
  throw InputError(path, line, 0, what);
}

// The extrinsic of a 4x4 matrix: last row 0 0 0 1, upper-left block s·R with R orthonormal.
Extrinsic FromMatrix(const Eigen::Matrix4d& m, const std::string& path) {
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (!std::isfinite(m(r, c))) Fail(path, r + 1, fmt::format("row {} column {} is {}, expected a finite number", r + 1, c + 1, m(r, c)));
    }
  }
  if (m.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) {
    Fail(path, 4, fmt::format("the last row is {} {} {} {}, expected 0 0 0 1 (a homogeneous transform)", m(3, 0),
                              m(3, 1), m(3, 2), m(3, 3)));
  }
  const Eigen::Matrix3d block = m.topLeftCorner<3, 3>();
  const double det = block.determinant();
  if (!(det > 0)) {
    Fail(path, 1, fmt::format("the rotation block has determinant {}, expected a rotation (det 1, or s^3 for a "
                              "scaled rotation; a reflection or singular matrix is not a pose transform)", det));
  }
  Extrinsic e;
  // A rotation given to a dozen digits has det 1 only to ~1e-13: that is rigid, and used as given (as evo does).
  const double scale = std::cbrt(det);
  e.scale = std::abs(scale - 1.0) <= kOrthonormalTolerance ? 1.0 : scale;
  e.rotation = block / e.scale;
  e.translation = m.topRightCorner<3, 1>();
  const double off = (e.rotation.transpose() * e.rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (off > kOrthonormalTolerance) {
    Fail(path, 1, fmt::format("the rotation block is not orthonormal (|R^T R - I| = {:.3g} > {:g} after taking out the "
                              "scale {:.9g}): expected a rotation matrix", off, kOrthonormalTolerance, e.scale));
  }
  return e;
}

Extrinsic FromJson(std::string_view content, const std::string& path) {
  const nlohmann::json j = ParseJsonInput(content, path, "a transform: x y z qx qy qz qw [scale]");
  if (!j.is_object()) Fail(path, 0, "expected a JSON object with the keys x y z qx qy qz qw (and optionally scale)");
  auto number = [&](const char* key) {
    if (!j.contains(key)) Fail(path, 0, fmt::format("missing key \"{}\": expected x y z qx qy qz qw (and optionally scale)", key));
    if (!j[key].is_number()) Fail(path, 0, fmt::format("{}: expected a number, got {}", key, j[key].dump()));
    const double v = j[key].get<double>();
    if (!std::isfinite(v)) Fail(path, 0, fmt::format("{}: expected a finite number, got {}", key, v));
    return v;
  };
  Extrinsic e;
  e.translation = {number("x"), number("y"), number("z")};
  const Eigen::Quaterniond q(number("qw"), number("qx"), number("qy"), number("qz"));
  if (std::abs(q.norm() - 1.0) > kOrthonormalTolerance) {
    Fail(path, 0, fmt::format("the quaternion (qx qy qz qw) has norm {:.9g}, expected a unit quaternion", q.norm()));
  }
  e.rotation = q.normalized().toRotationMatrix();
  if (j.contains("scale")) {
    e.scale = number("scale");
    if (!(e.scale > 0)) Fail(path, 0, fmt::format("scale: expected a positive number, got {}", e.scale));
  }
  return e;
}

Extrinsic FromText(std::string_view content, const std::string& path) {
  std::vector<double> values;
  int64_t line = 1;
  size_t i = 0;
  while (i < content.size()) {
    const char c = content[i];
    if (c == '\n') ++line;
    if (c == ' ' || c == '\t' || c == ',' || c == '\n' || c == '\r') {
      ++i;
      continue;
    }
    if (c == '#') {  // comment to the end of the line
      while (i < content.size() && content[i] != '\n') ++i;
      continue;
    }
    size_t end = i;
    while (end < content.size() && std::strchr(" \t,\r\n", content[end]) == nullptr) ++end;
    const std::string token(content.substr(i, end - i));
    char* stop = nullptr;
    const double v = std::strtod(token.c_str(), &stop);
    if (stop != token.c_str() + token.size()) {
      Fail(path, line, fmt::format("\"{}\" is not a number: expected a 4x4 matrix of 16 numbers", token));
    }
    values.push_back(v);
    i = end;
  }
  if (values.size() != 16) {
    Fail(path, line, fmt::format("{} numbers, expected a 4x4 matrix of 16 (4 rows of 4)", values.size()));
  }
  return FromMatrix(Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(values.data()), path);
}

// A 4x4 .npy array (common/npy.h: format versions 1-3, float64 or another numeric dtype, C or Fortran order).
Extrinsic FromNpy(std::string_view content, const std::string& path) {
  const NpyArray a = ParseNpy(content, path, "not a 4x4 float64 .npy array");
  if (a.shape != std::vector<uint64_t>{4, 4}) {
    std::string shape;
    for (uint64_t d : a.shape) shape += (shape.empty() ? "" : ", ") + std::to_string(d);
    Fail(path, 0, fmt::format("not a 4x4 float64 .npy array: shape is ({}), expected (4, 4)", shape));
  }
  Eigen::Matrix4d m;
  for (int k = 0; k < 16; ++k) m(k / 4, k % 4) = a.values[static_cast<size_t>(k)];
  return FromMatrix(m, path);
}

bool EndsWith(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

}  // namespace

Extrinsic ParseExtrinsic(std::string_view content, std::string_view format, const std::string& path) {
  if (format == "json") return FromJson(content, path);
  if (format == "npy") return FromNpy(content, path);
  return FromText(content, path);
}

Extrinsic ReadExtrinsic(const std::string& path) {
  const std::string content = ReadInputFile(path, kMaxBytes, "a transform file (.json, .npy or a 4x4 text matrix)");
  const std::string_view format = EndsWith(path, ".json") ? "json" : EndsWith(path, ".npy") ? "npy" : "matrix";
  return ParseExtrinsic(content, format, path);
}

traj::Trajectory TransformTrajectory(const traj::TrajectoryView& t, const Extrinsic* left, const Extrinsic* right) {
  const bool orientation = t.has_orientation();
  if (right != nullptr) {
    if (right->scale != 1.0) {
      throw UsageError(fmt::format("a right (body-frame) transform must be rigid, got scale {}", right->scale));
    }
    if (!right->translation.isZero(0) && !orientation) {
      throw UsageError("a right (body-frame) transform with a translation needs the trajectory's orientation, and it "
                       "is position only");
    }
    if (!right->translation.isZero(0) && t.has_velocity()) {
      throw UsageError("a right (body-frame) transform with a translation moves the body point, whose velocity would "
                       "need the angular velocity (v + w x R t): give a rotation-only right transform for files with "
                       "velocity columns");
    }
  }
  traj::Channels channels = t.channels();
  if (orientation) channels.orientation = traj::OrientationKind::kQuaternion;
  traj::Trajectory out(channels);
  out.Reserve(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    Eigen::Vector3d p = t.positions().col(i);
    Eigen::Matrix3d r = orientation ? t.Rotation(i) : Eigen::Matrix3d::Identity();
    Eigen::Vector3d v = t.has_velocity() ? Eigen::Vector3d(t.velocities().col(i)) : Eigen::Vector3d::Zero();
    Eigen::Vector3d w = t.has_angular_velocity() ? Eigen::Vector3d(t.angular_velocities().col(i)) : Eigen::Vector3d::Zero();
    if (right != nullptr) {
      p += r * right->translation;
      r = r * right->rotation;
      w = right->rotation.transpose() * w;
    }
    if (left != nullptr) {
      p = left->scale * (left->rotation * p) + left->translation;
      r = left->rotation * r;
      v = left->scale * (left->rotation * v);
    }
    const Eigen::Quaterniond q(r);
    const double xyzw[4] = {q.x(), q.y(), q.z(), q.w()};
    out.Append(t.stamps_ns()[static_cast<size_t>(i)], p.data(), orientation ? xyzw : nullptr, v.data(), w.data());
  }
  out.SetHasStamps(t.has_stamps());
  return out;
}

}  // namespace cheval::eval
