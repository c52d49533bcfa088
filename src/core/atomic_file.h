// Writing outputs so that a failure never leaves a half-written file: write to "<path>.tmp-<pid>",
// then rename over <path> on commit(). The destructor removes the temporary if commit() was not reached.
#pragma once

#include <fstream>
#include <string>

namespace hsr {

class AtomicFile {
 public:
  /// Opens the temporary file (binary mode). Throws hsr::Error(FileNotFound) if it cannot be created.
  explicit AtomicFile(const std::string& path, const std::string& stage = "write");
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ofstream& stream() { return out_; }
  /// Flushes, checks the stream and renames into place. Throws hsr::Error on failure.
  void commit();

 private:
  std::string path_, tmp_path_, stage_;
  std::ofstream out_;
  bool committed_ = false;
};

}  // namespace hsr
