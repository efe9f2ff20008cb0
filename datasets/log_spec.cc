#include "datasets/log_spec.h"

namespace slideid {

bool LogSpec::IsValid(std::string* why) const {
  if (log_every < 1) {
    if (why) *why = "log_every = " + std::to_string(log_every) + ": must be >= 1";
    return false;
  }
  return noise.IsValid(why);
}

bool LogSpec::IsValidFor(bool has_pushes, std::string* why) const {
  if (has_pushes && motion == LogMotion::kVelocities && push == LogPush::kPoint) {
    if (why) *why = "write = velocities needs push = moments: push points need the poses";
    return false;
  }
  if (has_pushes && wrench == LogWrench::kIntervalMean && push == LogPush::kPoint) {
    if (why) *why = "wrench = interval-mean needs push = moments: a mean wrench has no push point";
    return false;
  }
  return IsValid(why);
}

const char* ToString(LogMotion motion) {
  switch (motion) {
    case LogMotion::kPoses:
      return "poses";
    case LogMotion::kVelocities:
      return "velocities";
    case LogMotion::kBoth:
      return "both";
  }
  return "?";
}

const char* ToString(LogPush push) { return push == LogPush::kPoint ? "point" : "moments"; }

const char* ToString(LogWrench wrench) {
  return wrench == LogWrench::kAtRowTime ? "at-row-time" : "interval-mean";
}

bool ParseLogMotion(const std::string& text, LogMotion* motion) {
  for (LogMotion m : {LogMotion::kPoses, LogMotion::kVelocities, LogMotion::kBoth}) {
    if (text == ToString(m)) {
      *motion = m;
      return true;
    }
  }
  return false;
}

bool ParseLogPush(const std::string& text, LogPush* push) {
  for (LogPush p : {LogPush::kPoint, LogPush::kMoments}) {
    if (text == ToString(p)) {
      *push = p;
      return true;
    }
  }
  return false;
}

bool ParseLogWrench(const std::string& text, LogWrench* wrench) {
  for (LogWrench w : {LogWrench::kAtRowTime, LogWrench::kIntervalMean}) {
    if (text == ToString(w)) {
      *wrench = w;
      return true;
    }
  }
  return false;
}

}  // namespace slideid
