// tf2_msgs/TFMessage chains (docs/bags.md, "tf"): every transform of the dynamic and the static topic
// is collected per child frame; a pose of CHILD in PARENT at time t is the product of the edges from
// the common ancestor, each edge interpolated at t as tf2's BufferCore does.
#include <algorithm>
#include <map>
#include <set>

#include <Eigen/Geometry>

#include "message_reader.h"
#include "tf.h"

namespace cheval::bag {
namespace {

struct Transform {
  int64_t stamp_ns = 0;
  Eigen::Vector3d translation;
  Eigen::Quaterniond rotation;
};

struct Edge {
  std::string parent;
  bool is_static = false;
  std::vector<Transform> samples;  // sorted by stamp after reading; static: the last one
};

std::string StripSlash(std::string_view frame) {
  if (!frame.empty() && frame.front() == '/') frame.remove_prefix(1);
  return std::string(frame);
}

Transform Compose(const Transform& a, const Transform& b) {
  Transform out;
  out.stamp_ns = a.stamp_ns;
  out.rotation = a.rotation * b.rotation;
  out.translation = a.translation + a.rotation * b.translation;
  return out;
}

Transform Inverse(const Transform& a) {
  Transform out;
  out.stamp_ns = a.stamp_ns;
  out.rotation = a.rotation.conjugate();
  out.translation = -(out.rotation * a.translation);
  return out;
}

// The edge at `t`, or nullopt outside its recorded span (tf2's extrapolation error).
std::optional<Transform> At(const Edge& edge, int64_t t) {
  if (edge.is_static) return edge.samples.back();
  const std::vector<Transform>& s = edge.samples;
  if (t < s.front().stamp_ns || t > s.back().stamp_ns) return std::nullopt;
  const auto upper = std::lower_bound(s.begin(), s.end(), t, [](const Transform& a, int64_t v) { return a.stamp_ns < v; });
  if (upper->stamp_ns == t) return *upper;
  const Transform& one = *(upper - 1);
  const Transform& two = *upper;
  const double ratio = static_cast<double>(t - one.stamp_ns) / static_cast<double>(two.stamp_ns - one.stamp_ns);
  Transform out;
  out.stamp_ns = t;
  out.translation = (1.0 - ratio) * one.translation + ratio * two.translation;
  out.rotation = one.rotation.slerp(ratio, two.rotation);
  return out;
}

}  // namespace

std::optional<TfChain> ParseTfTopic(const std::string& topic) {
  const size_t colon = topic.find(':');
  if (colon == std::string::npos) return std::nullopt;
  TfChain chain;
  chain.topic = topic.substr(0, colon);
  const std::string frames = topic.substr(colon + 1);
  const size_t dot = frames.find('.');
  if (chain.topic.empty() || dot == std::string::npos || dot == 0 || dot + 1 == frames.size() ||
      frames.find('.', dot + 1) != std::string::npos) {
    throw UsageError(fmt::format("tf topic '{}': expected TOPIC:PARENT.CHILD, e.g. /tf:odom.base_link", topic));
  }
  chain.parent = StripSlash(frames.substr(0, dot));
  chain.child = StripSlash(frames.substr(dot + 1));
  return chain;
}

traj::Trajectory ReadTfTrajectory(const std::string& path, const TfChain& chain, bool record_time, const Walker& walk) {
  std::map<std::string, Edge> edges;  // child frame -> edge from its parent
  std::map<uint64_t, std::pair<Encoding, bool>> wanted;  // connection -> (encoding, static)
  std::set<std::string> topics;
  bool dynamic_found = false;
  Visitor visitor;
  visitor.on_connection = [&](uint64_t id, const Connection& c) {
    topics.insert(c.topic);
    const bool is_static = c.topic == chain.static_topic;
    if (c.topic != chain.topic && !is_static) return false;
    if (ShortType(c.type) != "tf2_msgs/TFMessage") {
      throw InputError(path, 0, 0, fmt::format("topic '{}' holds {} messages; a tf chain needs tf2_msgs/TFMessage",
                                               c.topic, c.type));
    }
    dynamic_found = dynamic_found || !is_static;
    wanted[id] = {c.encoding, is_static};
    return true;
  };
  int64_t count = 0;
  visitor.on_message = [&](uint64_t id, int64_t log_time_ns, std::string_view data) {
    ++count;
    const auto [encoding, is_static] = wanted[id];
    MessageReader reader(data, encoding, path, "tf2_msgs/TFMessage ", count);
    const uint32_t n = reader.U32();
    for (uint32_t i = 0; i < n; ++i) {
      std::string_view parent_view;
      Transform t;
      t.stamp_ns = reader.Header(&parent_view);
      if (record_time) t.stamp_ns = log_time_ns;
      const std::string parent = StripSlash(parent_view);
      const std::string child = StripSlash(reader.String());
      double v[7];
      reader.F64s(v, 7);
      t.translation = Eigen::Vector3d(v[0], v[1], v[2]);
      t.rotation = Eigen::Quaterniond(v[6], v[3], v[4], v[5]);
      const double norm = t.rotation.norm();
      if (!(norm > 1e-8) || !std::isfinite(norm) || !t.translation.allFinite()) {
        reader.Fail(fmt::format("transform {} -> {} has a zero or non-finite value", parent, child));
      }
      t.rotation.normalize();
      Edge& edge = edges[child];
      if (edge.samples.empty()) {
        edge.parent = parent;
        edge.is_static = is_static;
      } else if (edge.parent != parent) {
        throw InputError(path, 0, 0, fmt::format("tf frame '{}' has two parents, '{}' and '{}'", child, edge.parent,
                                                 parent));
      }
      if (edge.is_static != is_static) {
        throw InputError(path, 0, 0, fmt::format("tf frame '{}' is on both {} and {}", child, chain.topic,
                                                 chain.static_topic));
      }
      edge.samples.push_back(t);
    }
  };
  walk(visitor);
  if (!dynamic_found) {
    std::string list;
    for (const std::string& t : topics) list += (list.empty() ? "" : ", ") + t;
    throw InputError(path, 0, 0, fmt::format("no topic '{}' in the recording for the tf chain {}:{}.{}; its topics: {}",
                                             chain.topic, chain.topic, chain.parent, chain.child, list));
  }
  for (auto& [child, edge] : edges) {
    std::stable_sort(edge.samples.begin(), edge.samples.end(),
                     [](const Transform& a, const Transform& b) { return a.stamp_ns < b.stamp_ns; });
  }

  // The frames from `frame` up to its root.
  auto ancestors = [&](const std::string& frame) {
    std::vector<std::string> up{frame};
    while (true) {
      const auto it = edges.find(up.back());
      if (it == edges.end()) break;
      if (std::find(up.begin(), up.end(), it->second.parent) != up.end()) {
        throw InputError(path, 0, 0, fmt::format("tf frames form a loop through '{}'", it->second.parent));
      }
      up.push_back(it->second.parent);
    }
    return up;
  };
  const std::vector<std::string> from_child = ancestors(chain.child);
  const std::vector<std::string> from_parent = ancestors(chain.parent);
  const auto common = std::find_first_of(from_child.begin(), from_child.end(), from_parent.begin(), from_parent.end());
  const std::string name = fmt::format("{}:{}.{}", chain.topic, chain.parent, chain.child);
  if (common == from_child.end()) {
    throw ComputeError(fmt::format("{}: tf chain {} is broken: '{}' leads up to '{}', '{}' up to '{}'{}", path,
                                   name, chain.child, from_child.back(), chain.parent, from_parent.back(),
                                   edges.count(chain.child) == 0 && edges.count(chain.parent) == 0
                                       ? " (neither frame is in the transforms)"
                                       : ""));
  }
  const std::vector<std::string> child_side(from_child.begin(), common);
  const std::vector<std::string> parent_side(from_parent.begin(),
                                             std::find(from_parent.begin(), from_parent.end(), *common));

  // The stamps: the child's own edge, else the nearest dynamic edge of the chain.
  const Edge* stamps_edge = nullptr;
  for (const auto* side : {&child_side, &parent_side}) {
    for (const std::string& frame : *side) {
      const Edge& edge = edges.at(frame);
      if (stamps_edge == nullptr && !edge.is_static) stamps_edge = &edge;
    }
  }
  std::vector<int64_t> stamps;
  if (stamps_edge == nullptr) {
    stamps.push_back(child_side.empty() ? 0 : edges.at(child_side.front()).samples.back().stamp_ns);
  } else {
    for (const Transform& t : stamps_edge->samples) stamps.push_back(t.stamp_ns);
    stamps.erase(std::unique(stamps.begin(), stamps.end()), stamps.end());
  }

  traj::Trajectory trajectory;
  trajectory.Reserve(static_cast<Eigen::Index>(stamps.size()));
  for (const int64_t t : stamps) {
    auto chain_at = [&](const std::vector<std::string>& side) -> std::optional<Transform> {
      Transform total;  // T_ancestor_frame
      total.translation.setZero();
      total.rotation.setIdentity();
      for (auto it = side.rbegin(); it != side.rend(); ++it) {
        const std::optional<Transform> edge = At(edges.at(*it), t);
        if (!edge) return std::nullopt;
        total = Compose(total, *edge);
      }
      return total;
    };
    const std::optional<Transform> a_c = chain_at(child_side);
    const std::optional<Transform> a_p = chain_at(parent_side);
    if (!a_c || !a_p) continue;  // outside an edge's span, as evo skips tf2's extrapolation
    const Transform p_c = Compose(Inverse(*a_p), *a_c);
    const double position[3] = {p_c.translation.x(), p_c.translation.y(), p_c.translation.z()};
    const double orientation[4] = {p_c.rotation.x(), p_c.rotation.y(), p_c.rotation.z(), p_c.rotation.w()};
    trajectory.Append(t, position, orientation);
  }
  if (trajectory.empty()) {
    throw ComputeError(fmt::format("{}: tf chain {}: no stamp of '{}' lies inside every edge's recorded span",
                                   path, name, chain.child));
  }
  return trajectory;
}

}  // namespace cheval::bag
