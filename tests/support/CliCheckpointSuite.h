#pragma once
// `pyrolume render` interrupted, checkpointed and resumed as a user runs it
// (real signals, real files) with --backend cpu or vulkan: one body per case
// (the checks are AccumulationChecks.h's), instantiated for "cpu" by
// tests/unit/cli_checkpoint_test.cpp and for "vulkan" by
// tests/vulkan/cli_checkpoint_vulkan_test.cpp (BackendSuite.h explains the
// naming: CliCheckpoint.Name/"cpu", CliCheckpoint.Name/"vulkan").
#include <string>

#include <gtest/gtest.h>

#include "support/AccumulationChecks.h"
#include "support/BackendSuite.h"

namespace pyrolume::test {

// The backend is only a --backend argument here: no renderer in the test.
class CliCheckpoint : public ::testing::TestWithParam<std::string> {};

TEST_P(CliCheckpoint, SigintSavesThenResumeCompletesIdentically) { expect_cli_interrupt_then_resume(GetParam()); }

TEST_P(CliCheckpoint, SigtermSavesAndExits143) { expect_cli_sigterm_saves(GetParam()); }

TEST_P(CliCheckpoint, NonFiniteCheckpointIsRefused) { expect_nonfinite_checkpoint_refused(GetParam()); }

TEST_P(CliCheckpoint, NonFiniteSamplesAreReportedInStats) { expect_cli_reports_nonfinite_samples(GetParam()); }

TEST_P(CliCheckpoint, SigtermEndsAPassThroughAPathologicallyDenseMedium) {
  expect_sigterm_ends_a_pathological_pass(GetParam());
}

}  // namespace pyrolume::test
