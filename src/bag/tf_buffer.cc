// tf2's BufferCore as evo uses it (see tf_buffer.h). Each function names the tf2 code it follows;
// the arithmetic keeps tf2's operand order so that rounding is the same.
#include "tf_buffer.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cheval::bag {
namespace {

constexpr uint32_t kMaxGraphDepth = 1000;  // tf2's MAX_GRAPH_DEPTH

// Quaternion operator*(q1, q2).
TfQuat Mul(const TfQuat& a, const TfQuat& b) {
  return {a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, a.w * b.y + a.y * b.w + a.z * b.x - a.x * b.z,
          a.w * b.z + a.z * b.w + a.x * b.y - a.y * b.x, a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z};
}

// quatRotate(rotation, v): q = rotation * v; q *= rotation.inverse().
TfVec Rotate(const TfQuat& r, const TfVec& v) {
  const TfQuat q{r.w * v.x + r.y * v.z - r.z * v.y, r.w * v.y + r.z * v.x - r.x * v.z,
                 r.w * v.z + r.x * v.y - r.y * v.x, -r.x * v.x - r.y * v.y - r.z * v.z};
  const TfQuat i{-r.x, -r.y, -r.z, r.w};
  // Quaternion::operator*= (this = q, argument = i).
  return {q.w * i.x + q.x * i.w + q.y * i.z - q.z * i.y, q.w * i.y + q.y * i.w + q.z * i.x - q.x * i.z,
          q.w * i.z + q.z * i.w + q.x * i.y - q.y * i.x};
}

TfVec Add(const TfVec& a, const TfVec& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
TfVec Neg(const TfVec& a) { return {-a.x, -a.y, -a.z}; }
TfQuat Inverse(const TfQuat& q) { return {-q.x, -q.y, -q.z, q.w}; }
double Dot(const TfQuat& a, const TfQuat& b) { return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w; }

// tf2Acos: clamped to [-1, 1] first.
double Acos(double x) { return std::acos(x < -1.0 ? -1.0 : x > 1.0 ? 1.0 : x); }

// Quaternion::slerp (with angleShortestPath).
TfQuat Slerp(const TfQuat& a, const TfQuat& b, double t) {
  const double s = std::sqrt(Dot(a, a) * Dot(b, b));
  const double d = Dot(a, b);
  const TfQuat nb{-b.x, -b.y, -b.z, -b.w};
  const double angle = d < 0 ? Acos(Dot(a, nb) / s) * 2.0 : Acos(d / s) * 2.0;
  const double theta = angle / 2.0;
  if (theta == 0.0) return a;
  const double inv = 1.0 / std::sin(theta);
  const double s0 = std::sin((1.0 - t) * theta);
  const double s1 = std::sin(t * theta);
  if (d < 0) {
    return {(a.x * s0 + -b.x * s1) * inv, (a.y * s0 + -b.y * s1) * inv, (a.z * s0 + -b.z * s1) * inv,
            (a.w * s0 + -b.w * s1) * inv};
  }
  return {(a.x * s0 + b.x * s1) * inv, (a.y * s0 + b.y * s1) * inv, (a.z * s0 + b.z * s1) * inv,
          (a.w * s0 + b.w * s1) * inv};
}

// Vector3::setInterpolate3.
TfVec Lerp(const TfVec& a, const TfVec& b, double t) {
  const double s = 1.0 - t;
  return {s * a.x + t * b.x, s * a.y + t * b.y, s * a.z + t * b.z};
}

std::string StripSlash(const std::string& frame) { return !frame.empty() && frame[0] == '/' ? frame.substr(1) : frame; }

}  // namespace

int TfBuffer::Find(const std::string& name) const {
  const auto it = ids_.find(name);
  return it == ids_.end() ? 0 : it->second;
}

int TfBuffer::Frame(const std::string& name) {
  const int id = Find(name);
  if (id != 0) return id;
  ids_[name] = static_cast<int>(names_.size());
  names_.push_back(name);
  caches_.emplace_back();
  return static_cast<int>(names_.size()) - 1;
}

bool TfBuffer::Set(const std::string& parent_in, const std::string& child_in, const TfPose& pose, bool is_static) {
  const std::string parent = StripSlash(parent_in);
  const std::string child = StripSlash(child_in);
  const TfQuat& q = pose.rotation;
  const TfVec& v = pose.translation;
  if (child == parent || child.empty() || parent.empty()) return false;
  if (std::isnan(v.x) || std::isnan(v.y) || std::isnan(v.z) || std::isnan(q.x) || std::isnan(q.y) ||
      std::isnan(q.z) || std::isnan(q.w)) {
    return false;
  }
  if (!(std::abs((q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z) - 1.0) < 10e-3)) return false;
  const int child_id = Frame(child);
  const int parent_id = Frame(parent);
  Cache& cache = caches_[static_cast<size_t>(child_id)];
  if (!cache.exists || cache.is_static != is_static) cache = Cache{true, is_static, {}};  // allocateFrame
  const Sample sample{pose.stamp_ns, parent_id, v, q};
  if (is_static) {
    cache.samples.assign(1, sample);  // StaticCache::insertData keeps the last
    return true;
  }
  cache.samples.push_back(sample);  // sorted, checked and pruned in Finish()
  return true;
}

void TfBuffer::Finish() {
  for (Cache& cache : caches_) {
    if (!cache.exists || cache.is_static || cache.samples.empty()) continue;
    std::vector<Sample>& s = cache.samples;
    // TimeCache::insertData prunes (older than its newest minus the cache time) before each insert
    // and refuses what is already that old: what is left at the end is every sample not older than
    // the newest stamp before the last insert, minus the cache time.
    int64_t latest_before_last = std::numeric_limits<int64_t>::min();
    for (size_t i = 0; i + 1 < s.size(); ++i) latest_before_last = std::max(latest_before_last, s[i].stamp_ns);
    if (s.size() > 1) {
      const int64_t oldest = latest_before_last - cache_time_ns_;
      s.erase(std::remove_if(s.begin(), s.end(), [&](const Sample& x) { return x.stamp_ns < oldest; }), s.end());
    }
    // Inserted before the equal stamps already there in a newest-first list: ascending, equal stamps
    // keep their insertion order. An exact duplicate is not inserted again.
    std::stable_sort(s.begin(), s.end(), [](const Sample& a, const Sample& b) { return a.stamp_ns < b.stamp_ns; });
    std::vector<Sample> kept;
    kept.reserve(s.size());
    for (const Sample& x : s) {
      bool duplicate = false;
      for (auto it = kept.rbegin(); it != kept.rend() && it->stamp_ns == x.stamp_ns; ++it) {
        duplicate = duplicate || (it->parent == x.parent && it->translation.x == x.translation.x &&
                                  it->translation.y == x.translation.y && it->translation.z == x.translation.z &&
                                  it->rotation.x == x.rotation.x && it->rotation.y == x.rotation.y &&
                                  it->rotation.z == x.rotation.z && it->rotation.w == x.rotation.w);
      }
      if (!duplicate) kept.push_back(x);
    }
    s.swap(kept);
  }
}

bool TfBuffer::Get(const Cache& cache, int64_t time, Sample* out) const {
  const std::vector<Sample>& s = cache.samples;
  if (s.empty()) return false;
  if (cache.is_static) {  // StaticCache::getData: the transform, stamped at the time asked
    *out = s.front();
    out->stamp_ns = time;
    return true;
  }
  // TimeCache::findClosest.
  if (time == 0 || time == s.back().stamp_ns) {
    *out = s.back();
    return true;
  }
  if (s.size() == 1) return false;
  if (time == s.front().stamp_ns) {
    *out = s.front();
    return true;
  }
  if (time > s.back().stamp_ns || time < s.front().stamp_ns) return false;
  const auto after = std::upper_bound(s.begin(), s.end(), time,
                                      [](int64_t t, const Sample& x) { return t < x.stamp_ns; });
  const Sample& one = *(after - 1);  // the last with stamp <= time
  const Sample& two = *after;
  if (one.parent != two.parent) {
    *out = one;
    return true;
  }
  // TimeCache::interpolate.
  if (two.stamp_ns == one.stamp_ns) {
    *out = two;
    return true;
  }
  const double ratio =
      static_cast<double>(time - one.stamp_ns) / static_cast<double>(two.stamp_ns - one.stamp_ns);
  out->translation = Lerp(one.translation, two.translation, ratio);
  out->rotation = Slerp(one.rotation, two.rotation, ratio);
  out->stamp_ns = one.stamp_ns;
  out->parent = one.parent;
  return true;
}

std::pair<int64_t, int> TfBuffer::LatestAndParent(const Cache& cache) const {
  if (cache.samples.empty()) return {0, 0};
  if (cache.is_static) return {0, cache.samples.front().parent};
  return {cache.samples.back().stamp_ns, cache.samples.back().parent};
}

TfStatus TfBuffer::LatestCommonTime(const std::string& target, const std::string& source, int64_t* time) const {
  const int target_id = Find(target);
  const int source_id = Find(source);
  if (source_id == 0 || target_id == 0) return TfStatus::kUnknownFrame;
  if (source_id == target_id) {
    const Cache& c = caches_[static_cast<size_t>(source_id)];
    *time = c.exists ? LatestAndParent(c).first : 0;
    return TfStatus::kOk;
  }
  constexpr int64_t kMax = std::numeric_limits<int64_t>::max();
  std::vector<std::pair<int64_t, int>> chain;
  int64_t common = kMax;
  int frame = source_id;
  for (uint32_t depth = 0; frame != 0; ++depth) {
    const Cache& c = caches_[static_cast<size_t>(frame)];
    if (!c.exists) break;
    const std::pair<int64_t, int> latest = LatestAndParent(c);
    if (latest.second == 0) break;
    if (latest.first != 0) common = std::min(latest.first, common);
    chain.push_back(latest);
    frame = latest.second;
    if (frame == target_id) {
      *time = common == kMax ? 0 : common;
      return TfStatus::kOk;
    }
    if (depth + 1 > kMaxGraphDepth) return TfStatus::kLoop;
  }
  frame = target_id;
  common = kMax;
  int common_parent = 0;
  for (uint32_t depth = 0;; ++depth) {
    const Cache& c = caches_[static_cast<size_t>(frame)];
    if (!c.exists) break;
    const std::pair<int64_t, int> latest = LatestAndParent(c);
    if (latest.second == 0) break;
    if (latest.first != 0) common = std::min(latest.first, common);
    const auto it = std::find_if(chain.begin(), chain.end(), [&](const auto& p) { return p.second == latest.second; });
    if (it != chain.end()) {
      common_parent = it->second;
      break;
    }
    frame = latest.second;
    if (frame == source_id) {
      *time = common == kMax ? 0 : common;
      return TfStatus::kOk;
    }
    if (depth + 1 > kMaxGraphDepth) return TfStatus::kLoop;
  }
  if (common_parent == 0) return TfStatus::kConnectivity;
  for (const auto& [stamp, parent] : chain) {
    if (stamp != 0) common = std::min(common, stamp);
    if (parent == common_parent) break;
  }
  *time = common == kMax ? 0 : common;
  return TfStatus::kOk;
}

TfStatus TfBuffer::Lookup(const std::string& target, const std::string& source, int64_t time, TfPose* out) const {
  *out = TfPose{};
  if (target == source) {  // lookupTransformImpl's identity
    const Cache& c = caches_[static_cast<size_t>(Find(target))];
    out->stamp_ns = time == 0 && c.exists ? LatestAndParent(c).first : time;
    return TfStatus::kOk;
  }
  const int target_id = Find(target);
  const int source_id = Find(source);
  if (target_id == 0 || source_id == 0) return TfStatus::kUnknownFrame;
  if (time == 0) {
    const TfStatus status = LatestCommonTime(target, source, &time);
    if (status != TfStatus::kOk) return status;
  }
  // walkToTopParent with TransformAccum.
  TfVec source_vec, target_vec;
  TfQuat source_quat, target_quat;
  Sample st{};
  auto finish = [&](const TfVec& v, const TfQuat& q) {
    out->stamp_ns = time;
    out->translation = v;
    out->rotation = q;
    return TfStatus::kOk;
  };
  int frame = source_id;
  int top_parent = frame;
  bool extrapolation_might_have_occurred = false;
  for (uint32_t depth = 0; frame != 0;) {
    const Cache& c = caches_[static_cast<size_t>(frame)];
    if (!c.exists) {
      top_parent = frame;
      break;
    }
    if (!Get(c, time, &st)) {
      top_parent = frame;
      extrapolation_might_have_occurred = true;
      break;
    }
    if (frame == target_id) return finish(source_vec, source_quat);  // TargetParentOfSource
    source_vec = Add(Rotate(st.rotation, source_vec), st.translation);
    source_quat = Mul(st.rotation, source_quat);
    top_parent = frame;
    frame = st.parent;
    if (++depth > kMaxGraphDepth) return TfStatus::kLoop;
  }
  frame = target_id;
  for (uint32_t depth = 0; frame != top_parent;) {
    const Cache& c = caches_[static_cast<size_t>(frame)];
    if (!c.exists) break;
    if (!Get(c, time, &st)) return TfStatus::kExtrapolation;
    if (frame == source_id) {  // SourceParentOfTarget
      const TfQuat inv = Inverse(target_quat);
      return finish(Rotate(inv, Neg(target_vec)), inv);
    }
    target_vec = Add(Rotate(st.rotation, target_vec), st.translation);
    target_quat = Mul(st.rotation, target_quat);
    frame = st.parent;
    if (++depth > kMaxGraphDepth) return TfStatus::kLoop;
  }
  if (frame != top_parent) {
    return extrapolation_might_have_occurred ? TfStatus::kExtrapolation : TfStatus::kConnectivity;
  }
  const TfQuat inv = Inverse(target_quat);  // FullPath
  const TfVec inv_vec = Rotate(inv, Neg(target_vec));
  return finish(Add(Rotate(inv, source_vec), inv_vec), Mul(inv, source_quat));
}

std::string TfBuffer::Root(const std::string& frame) const {
  int id = Find(frame);
  if (id == 0) return "";
  for (uint32_t depth = 0; depth <= kMaxGraphDepth; ++depth) {
    const Cache& c = caches_[static_cast<size_t>(id)];
    const int parent = c.exists ? LatestAndParent(c).second : 0;
    if (parent == 0) return names_[static_cast<size_t>(id)];
    id = parent;
  }
  return names_[static_cast<size_t>(id)];
}

}  // namespace cheval::bag
