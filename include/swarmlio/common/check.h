// The one place where the project chooses its CHECK implementation.
//
// CHECKs are for programmer errors only (a violated invariant, an index out of
// range from our own code). Bad input from files, sockets or configs is a
// Status (status.h), never a CHECK. Ceres 2.1 uses glog; so do we, behind this
// header, so that a later switch (e.g. to Abseil logging) touches one file.
#pragma once

#include <glog/logging.h>  // IWYU pragma: export
