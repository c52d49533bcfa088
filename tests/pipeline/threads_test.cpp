// The output does not depend on the thread count (issue 16): the whole pipeline with one worker thread and
// with two gives the same mesh file, byte for byte, and the same report figures; on a scan with normals and
// on one without (estimated and MST-oriented normals).
#include "core/threads.h"
#include "io/io.h"
#include "pipeline/pipeline.h"
#include "synth/synth.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <cstdlib>

namespace hsr {
namespace {

std::string mesh_bytes(const PolygonMesh& mesh, const std::string& name) {
  const auto path = test::scratch_dir(name) / "mesh.obj";
  write_mesh(path.string(), mesh);
  return test::read_file(path);
}

TEST(Threads, OneOrTwoThreadsSameBytes) {
  for (const char* model : {"courtyard", "dormer_house"})
    for (bool normals : {true, false}) {
      SynthParams sp;
      sp.target_points = 80000;
      PointCloud cloud = run_synth(model, sp).cloud;
      if (!normals) cloud.normals.clear();
      const std::string name = std::string(model) + (normals ? "" : "_raw");
      PipelineParams one, two;
      one.threads = 1;
      two.threads = 2;
      const PipelineResult a = run_pipeline(cloud, one);
      const PipelineResult b = run_pipeline(cloud, two);
      EXPECT_EQ(a.report["threads"], 1);
      EXPECT_EQ(b.report["threads"], 2);
      EXPECT_EQ(mesh_bytes(a.mesh, name + "_1"), mesh_bytes(b.mesh, name + "_2")) << name;
      EXPECT_EQ(a.report["counts"], b.report["counts"]) << name;
      EXPECT_EQ(a.report["accuracy"], b.report["accuracy"]) << name;
      EXPECT_GT(a.mesh.num_faces(), 6u) << name;
    }
}

TEST(Threads, EnvironmentVariableSetsTheCount) {
  ::setenv("HSR_THREADS", "1", 1);
  EXPECT_EQ(resolve_thread_count(0), 1);
  EXPECT_EQ(resolve_thread_count(3), 3);  // an explicit count wins
  ::setenv("HSR_THREADS", "zero", 1);
  EXPECT_EQ(resolve_thread_count(0), 0);  // not a positive integer: ignored
  ::unsetenv("HSR_THREADS");
  EXPECT_EQ(resolve_thread_count(0), 0);
}

}  // namespace
}  // namespace hsr
