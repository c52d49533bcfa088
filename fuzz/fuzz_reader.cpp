// libFuzzer target for one reader of stage io (HSR_FUZZ_EXT = ply, xyz, off or las). The readers take a
// path, so the input bytes are written to a per-process temporary file with that extension, then checked
// against reader_contract.h; a violation aborts, which libFuzzer reports as a crash (as it does crashes,
// leaks, sanitizer reports, timeouts and allocations above -malloc_limit_mb).
#include "core/log.h"
#include "reader_contract.h"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#ifndef HSR_FUZZ_EXT
#error "HSR_FUZZ_EXT must name the extension"
#endif

namespace {

std::string temp_path(const char* ext) {
  const char* dir = std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
  return std::string(dir) + "/hsr-fuzz-" + std::to_string(::getpid()) + "." + ext;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  hsr::log::set_level(hsr::log::Level::Quiet);  // the readers' warnings would flood the fuzzer's output
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = temp_path(HSR_FUZZ_EXT);
  static const std::string scratch = temp_path("rt.ply");
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    hsr::fuzz::check_reader_contract(path, scratch);
  } catch (const hsr::fuzz::ReaderContractViolation& v) {
    std::fprintf(stderr, "fuzz contract violated: %s\n", v.what());
    std::abort();
  }
  return 0;
}
