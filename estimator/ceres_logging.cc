#include "estimator/ceres_logging.h"

#include <glog/logging.h>

namespace slideid {

void SetCeresLogging(bool quiet) {
  FLAGS_minloglevel = quiet ? google::GLOG_FATAL : google::GLOG_INFO;
}

}  // namespace slideid
