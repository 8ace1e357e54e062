// tf2_msgs/TFMessage chains (docs/bags.md, "tf chains"), as evo reads them (evo/tools/tf_cache.py):
// every transform of the dynamic topic, then of the static topic, each in log-time order, goes into a
// tf2 buffer (tf_buffer.h); the chain is looked up every 0.1 s (evo's tf_cache_lookup_frequency) from
// the recording's start up to the latest time common to the chain's edges, and the times tf2 cannot
// answer without extrapolating are left out.
#include <algorithm>
#include <cmath>
#include <set>

#include "message_reader.h"
#include "tf.h"
#include "tf_buffer.h"

namespace cheval::bag {
namespace {

std::string StripSlash(std::string_view frame) {
  if (!frame.empty() && frame.front() == '/') frame.remove_prefix(1);
  return std::string(frame);
}

struct Received {
  int64_t log_time_ns;
  std::string parent, child;
  TfPose pose;
};

}  // namespace

std::optional<TfChain> ParseTfTopic(const std::string& topic) {
  // evo's tf_id.split_id: TOPIC ':' PARENT '.' CHILD [':' STATIC_TOPIC]; the child is all after the
  // first '.'.
  const size_t colon = topic.find(':');
  if (colon == std::string::npos) return std::nullopt;
  TfChain chain;
  chain.topic = topic.substr(0, colon);
  std::string frames = topic.substr(colon + 1);
  const size_t second = frames.rfind(':');
  if (second != std::string::npos) {
    chain.static_topic = frames.substr(second + 1);
    frames = frames.substr(0, second);
  }
  const size_t dot = frames.find('.');
  if (chain.topic.empty() || dot == std::string::npos || dot == 0 || dot + 1 == frames.size() ||
      chain.static_topic.empty()) {
    throw UsageError(fmt::format("tf topic '{}': expected TOPIC:PARENT.CHILD[:STATIC_TOPIC], e.g. /tf:odom.base_link",
                                 topic));
  }
  chain.parent = StripSlash(frames.substr(0, dot));
  chain.child = StripSlash(frames.substr(dot + 1));
  return chain;
}

traj::Trajectory ReadTfTrajectory(const std::string& path, const TfChain& chain, bool record_time, const Walker& walk) {
  std::map<uint64_t, std::pair<Encoding, bool>> wanted;  // connection -> (encoding, static)
  std::set<std::string> topics;
  bool dynamic_found = false;
  std::vector<Received> dynamic, fixed;  // fixed: the static topic's transforms
  int64_t start_ns = -1;
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
      Received r;
      r.log_time_ns = log_time_ns;
      r.pose.stamp_ns = reader.Header(&parent_view);
      if (record_time) r.pose.stamp_ns = log_time_ns;
      r.parent = std::string(parent_view);
      r.child = std::string(reader.String());
      double v[7];
      reader.F64s(v, 7);
      if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
        reader.Fail(fmt::format("transform {} -> {} has a non-finite translation", r.parent, r.child));
      }
      r.pose.translation = {v[0], v[1], v[2]};
      r.pose.rotation = {v[3], v[4], v[5], v[6]};
      (is_static ? fixed : dynamic).push_back(std::move(r));
    }
  };
  visitor.on_start_time = [&](int64_t t) { start_ns = t; };
  walk(visitor);
  if (!dynamic_found) {
    std::string list;
    for (const std::string& t : topics) list += (list.empty() ? "" : ", ") + t;
    throw InputError(path, 0, 0, fmt::format("no topic '{}' in the recording for the tf chain {}:{}.{}; its topics: {}",
                                             chain.topic, chain.topic, chain.parent, chain.child, list));
  }
  // evo reads the dynamic topic, then the static one, each in log-time order (rosbags' order).
  TfBuffer buffer;
  for (std::vector<Received>* list : {&dynamic, &fixed}) {
    std::stable_sort(list->begin(), list->end(),
                     [](const Received& a, const Received& b) { return a.log_time_ns < b.log_time_ns; });
    for (const Received& r : *list) buffer.Set(r.parent, r.child, r.pose, list == &fixed);
  }
  buffer.Finish();

  const std::string name = fmt::format("{}:{}.{}", chain.topic, chain.parent, chain.child);
  auto fail = [&](TfStatus status, int64_t t) {
    switch (status) {
      case TfStatus::kUnknownFrame:
        throw ComputeError(fmt::format("{}: tf chain {} is broken: frame '{}' is in no transform of {} or {}", path, name,
                                       buffer.Root(chain.parent).empty() ? chain.parent : chain.child, chain.topic,
                                       chain.static_topic));
      case TfStatus::kLoop:
        throw ComputeError(fmt::format("{}: tf chain {}: the tf frames form a loop", path, name));
      default:
        throw ComputeError(fmt::format("{}: tf chain {} is broken{}: '{}' leads up to '{}', '{}' up to '{}'", path,
                                       name, t == 0 ? "" : fmt::format(" at {} ns", t), chain.child,
                                       buffer.Root(chain.child), chain.parent, buffer.Root(chain.parent)));
    }
  };
  int64_t latest = 0;
  const TfStatus common = buffer.LatestCommonTime(chain.parent, chain.child, &latest);
  if (common != TfStatus::kOk) fail(common, 0);
  // evo's lookup times: from the recording's start every 0.1 s while <= the latest common time; a
  // chain of static edges only (latest common time 0, before the start) is looked up once, at 0.
  constexpr int64_t kStepNs = 100000000;       // 1 / tf_cache_lookup_frequency (10 Hz)
  constexpr int64_t kMaxLookups = 10000000;     // 11.6 days at 10 Hz
  const bool once = start_ns < 0 || latest < start_ns;
  const int64_t lookups = once ? 1 : (latest - start_ns) / kStepNs + 1;
  if (lookups > kMaxLookups) {
    throw ComputeError(fmt::format("{}: tf chain {}: {} lookups from the recording's start ({} ns) every 0.1 s to the "
                                   "latest common time ({} ns); more than {} is taken for broken stamps",
                                   path, name, lookups, start_ns, latest, kMaxLookups));
  }
  traj::Trajectory trajectory;
  for (int64_t k = 0; k < lookups; ++k) {
    const int64_t t = once ? latest : start_ns + k * kStepNs;
    TfPose pose;
    const TfStatus status = buffer.Lookup(chain.parent, chain.child, t, &pose);
    if (status == TfStatus::kExtrapolation) continue;  // evo skips tf2's ExtrapolationException
    if (status != TfStatus::kOk) fail(status, t);
    const double position[3] = {pose.translation.x, pose.translation.y, pose.translation.z};
    const double orientation[4] = {pose.rotation.x, pose.rotation.y, pose.rotation.z, pose.rotation.w};
    if (!std::all_of(position, position + 3, [](double x) { return std::isfinite(x); }) ||
        !std::all_of(orientation, orientation + 4, [](double x) { return std::isfinite(x); })) {
      throw ComputeError(fmt::format("{}: tf chain {}: the pose at {} ns is not finite (the transforms' products "
                                     "overflow)",
                                     path, name, t));
    }
    trajectory.Append(pose.stamp_ns, position, orientation);
  }
  if (trajectory.empty()) {
    throw ComputeError(fmt::format("{}: tf chain {}: no lookup time from the recording's start every 0.1 s up to the "
                                   "latest common time ({} ns) lies inside every edge's transforms",
                                   path, name, latest));
  }
  return trajectory;
}

}  // namespace cheval::bag
