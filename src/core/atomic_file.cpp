#include "core/atomic_file.h"
#include "core/error.h"

#include <cstdio>
#include <filesystem>
#include <unistd.h>

namespace hsr {

AtomicFile::AtomicFile(const std::string& path, const std::string& stage)
    : path_(path), tmp_path_(path + ".tmp-" + std::to_string(::getpid())), stage_(stage) {
  out_.open(tmp_path_, std::ios::binary | std::ios::trunc);
  if (!out_) throw Error(Status::FileNotFound, stage_, "cannot create output file '" + path_ + "'");
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::error_code ec;
    std::filesystem::remove(tmp_path_, ec);
  }
}

void AtomicFile::commit() {
  out_.flush();
  bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok) throw Error(Status::Internal, stage_, "writing '" + path_ + "' failed (disk full?)");
  std::error_code ec;
  std::filesystem::rename(tmp_path_, path_, ec);
  if (ec) throw Error(Status::FileNotFound, stage_, "cannot move output into place at '" + path_ + "': " + ec.message());
  committed_ = true;
}

}  // namespace hsr
