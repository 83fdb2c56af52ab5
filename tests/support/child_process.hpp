// Test helpers around the project's processes: where the binaries are, temporary directories.
#pragma once

#include <string>

#include "common/process.hpp"

namespace auvrl::test_support {

using ChildProcess = process::ChildProcess;

/// Path of one of the project's executables (build/bin/NAME).
std::string bin_path(const std::string& name);

/// A fresh temporary directory for a test's files, removed when the test program ends unless a
/// test failed (or AUVRL_KEEP_TEST_DIRS is set).
std::string make_temp_dir(const std::string& prefix);

}  // namespace auvrl::test_support
