#pragma once
// tf chains: `/tf:PARENT.CHILD` looked up through the tree of /tf and /tf_static. Internal to src/bag.
#include <optional>
#include <string>

#include "cheval/bag/bag.h"
#include "container.h"

namespace cheval::bag {

struct TfChain {
  std::string topic;  // the dynamic topic, e.g. /tf
  std::string static_topic = "/tf_static";
  std::string parent, child;
};

// The chain of a `TOPIC:PARENT.CHILD` topic; nullopt for a topic without ':'. UsageError when the
// part after ':' is not two frame names separated by one '.'.
std::optional<TfChain> ParseTfTopic(const std::string& topic);


// The poses of `chain.child` in `chain.parent` at the stamps of the child's own (or, when that edge is
// static, its nearest dynamic ancestor's) transforms, tf2's interpolation between transforms of each
// edge (linear translation, slerp rotation); stamps outside an edge's recorded span are skipped, as
// evo skips tf2's extrapolation errors. ComputeError when the frames are not connected or no stamp
// can be looked up; InputError when the topic is missing or holds no TFMessage.
traj::Trajectory ReadTfTrajectory(const std::string& path, const TfChain& chain, bool record_time, const Walker& walk);

}  // namespace cheval::bag
