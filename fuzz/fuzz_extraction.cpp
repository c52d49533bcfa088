// libFuzzer target: extraction -> writers -> eval on random exact cell complexes and labelings
// (fuzz_complex.h: the byte format and the contract). A broken contract, a crash, a sanitizer report or a
// hang (libFuzzer -timeout) is a finding; tests/reliability replays the findings.
#include "core/log.h"
#include "fuzz_complex.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace {

std::string& scratch() {
  static std::string dir;
  return dir;
}

void remove_scratch() {
  std::error_code ec;
  std::filesystem::remove_all(scratch(), ec);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  hsr::log::set_level(hsr::log::Level::Quiet);
  scratch() = (std::filesystem::temp_directory_path() / ("hsr_fuzz_extraction_" + std::to_string(getpid()))).string();
  std::filesystem::create_directories(scratch());
  std::atexit(remove_scratch);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const hsr::fuzz::ComplexCase c = hsr::fuzz::decode_complex_case(data, size);
  const std::string problem = hsr::fuzz::check_extraction_case(c, scratch());
  if (!problem.empty()) {
    std::fprintf(stderr, "fuzz contract violated: %s\n", problem.c_str());
    std::abort();
  }
  return 0;
}
