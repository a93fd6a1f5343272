// BackgroundCheckpointWriter: checkpoints handed over faster than they are written end with the
// newest on disk (read back by read_checkpoint, the iterates bit for bit), and a directory that
// cannot be written makes finish() throw naming the file.

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <string>

#include "../test_files.hpp"
#include "coupling/checkpoint.hpp"

namespace robin {
namespace {

/// The checkpoint after iteration k: iterates x_j = (j, j + 0.5, ...) and a history record per
/// iteration, the loop not stopped.
RunCheckpoint checkpoint_after(int k) {
  RunCheckpoint checkpoint;
  checkpoint.run_id = "0123456789abcdef0123456789abcdef";
  checkpoint.first_run_id = checkpoint.run_id;
  checkpoint.started = "2026-11-29T15:00:00Z";
  checkpoint.case_file = "/nowhere/case.toml";
  checkpoint.case_text = "title = \"x\"\n";
  checkpoint.iteration.iteration = k;
  for (int j = 1; j <= k; ++j) {
    checkpoint.iteration.iterates.push_back(Eigen::VectorXd::LinSpaced(7, j, j + 0.5 * 6));
    IterationRecord record;
    record.iteration = j;
    record.obstacle_change = 1.0 / j;
    checkpoint.iteration.history.push_back(record);
  }
  checkpoint.iteration.next_iterate = Eigen::VectorXd::Constant(7, k + 1.0);
  return checkpoint;
}

TEST(BackgroundCheckpoint, TheNewestHandedOverIsOnDiskAfterFinish) {
  const testing::TemporaryDirectory directory("background-checkpoint");
  BackgroundCheckpointWriter writer(directory.path());
  for (int k = 1; k <= 40; ++k) writer.write(checkpoint_after(k));
  writer.finish();
  const RunCheckpoint read = read_checkpoint(directory.path());
  EXPECT_EQ(read.iteration.iteration, 40);
  const RunCheckpoint expected = checkpoint_after(40);
  ASSERT_EQ(read.iteration.iterates.size(), expected.iteration.iterates.size());
  for (std::size_t j = 0; j < expected.iteration.iterates.size(); ++j) {
    EXPECT_EQ(read.iteration.iterates[j], expected.iteration.iterates[j]) << j;
  }
}

TEST(BackgroundCheckpoint, AnUnwritableDirectoryIsThrownByFinish) {
  const testing::TemporaryDirectory directory("background-checkpoint-missing");
  BackgroundCheckpointWriter writer(directory.path() / "no" / "such" / "directory");
  writer.write(checkpoint_after(1));
  try {
    writer.finish();
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("checkpoint"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace robin
