#pragma once
// A transform buffer that answers as tf2's BufferCore (ROS 2 geometry2, tf2/src/buffer_core.cpp and
// cache.cpp) answers evo: the same caches (static: the last transform; dynamic: every stamp, pruned
// to the cache time), the same choice of the transforms around a time, the same walk up the tree and
// the same arithmetic in the same order (tf2/LinearMath), so that a lookup gives evo's pose to the
// bit. Internal to src/bag.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace cheval::bag {

// tf2's Quaternion and Vector3, as plain doubles.
struct TfQuat {
  double x = 0, y = 0, z = 0, w = 1;
};
struct TfVec {
  double x = 0, y = 0, z = 0;
};

struct TfPose {
  int64_t stamp_ns = 0;
  TfVec translation;
  TfQuat rotation;
};

enum class TfStatus { kOk, kExtrapolation, kConnectivity, kUnknownFrame, kLoop };

class TfBuffer {
 public:
  // tf2's cache time (evo's `tf_cache_max_time`, 1e4 s by default).
  explicit TfBuffer(int64_t cache_time_ns = 10000LL * 1000000000LL) : cache_time_ns_(cache_time_ns) {}

  // BufferCore::setTransform: frames lose a leading '/'; a transform to itself, without a frame, with
  // a NaN or with a quaternion whose squared norm is 1e-2 or more away from 1 is ignored (returns
  // false), as tf2 ignores it. A frame's cache is replaced when a transform of the other kind
  // (static or dynamic) arrives for it.
  bool Set(const std::string& parent, const std::string& child, const TfPose& pose, bool is_static);

  // Sorts and prunes the dynamic caches; call once after the last Set.
  void Finish();

  // BufferCore::getLatestCommonTime(target, source).
  TfStatus LatestCommonTime(const std::string& target, const std::string& source, int64_t* time) const;

  // BufferCore::lookupTransform(target, source, time): the pose of `source` in `target`.
  TfStatus Lookup(const std::string& target, const std::string& source, int64_t time, TfPose* out) const;

  // The frame a frame hangs from at its newest transform, and the root above it ("" when unknown).
  std::string Root(const std::string& frame) const;

 private:
  struct Sample {
    int64_t stamp_ns;
    int parent;
    TfVec translation;
    TfQuat rotation;
  };
  struct Cache {
    bool exists = false;
    bool is_static = false;
    std::vector<Sample> samples;  // ascending stamps; equal stamps in insertion order
  };

  int Frame(const std::string& name);
  int Find(const std::string& name) const;
  // TimeCache::getData / StaticCache::getData.
  bool Get(const Cache& cache, int64_t time, Sample* out) const;
  // (latest stamp, parent) of TimeCache::getLatestTimeAndParent; parent 0 for an empty cache.
  std::pair<int64_t, int> LatestAndParent(const Cache& cache) const;

  int64_t cache_time_ns_;
  std::map<std::string, int> ids_;
  std::vector<std::string> names_{"NO_PARENT"};
  std::vector<Cache> caches_{Cache{}};
};

}  // namespace cheval::bag
