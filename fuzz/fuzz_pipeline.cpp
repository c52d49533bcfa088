// libFuzzer target for the whole pipeline (structure → … → eval) on tiny clouds decoded from the input
// bytes (fuzz_cloud.h: at most 200 points, partitioner, scale, offset, detector and plane size chosen by the
// bytes). Contract: run_pipeline either returns a valid mesh or throws hsr::Error naming a stage with a
// user-facing status (BadInput, NoPlanes, DegenerateInput, InvalidOutput, NotImplemented). Status::Internal,
// any other exception, a crash, a sanitizer report or a hang (libFuzzer -timeout) is a finding.
#include "core/error.h"
#include "core/log.h"
#include "fuzz_cloud.h"

#include <cstdio>
#include <cstdlib>

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  hsr::log::set_level(hsr::log::Level::Quiet);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const hsr::fuzz::FuzzCase c = hsr::fuzz::decode_fuzz_case(data, size);
  try {
    const hsr::PipelineResult r = hsr::run_pipeline(c.cloud, c.params);
    if (!r.eval.validity.valid()) {
      std::fprintf(stderr, "fuzz contract violated: invalid mesh returned without --force\n");
      std::abort();
    }
  } catch (const hsr::Error& e) {
    using hsr::Status;
    const Status s = e.status();
    const bool clean = s == Status::BadInput || s == Status::NoPlanes || s == Status::DegenerateInput ||
                       s == Status::InvalidOutput || s == Status::NotImplemented;
    if (!clean || e.stage().empty()) {
      std::fprintf(stderr, "fuzz contract violated: %s %s\n", hsr::status_name(s), e.one_line().c_str());
      std::abort();
    }
  }
  return 0;
}
