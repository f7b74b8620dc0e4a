// nhdyn_test::scratch_dir(name): a folder for one test program's files,
// <temp>/nhdyn_test_<name>_<pid>, made empty on first use and removed with everything in it when
// the program exits normally. Each run of the suite used to leave its programs' folders behind
// (the viewer test's alone 61 MB a run). NHDYN_KEEP_TEST_FILES=1 keeps them, and the program
// prints where, to look at a failure's files.
#pragma once
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <system_error>

namespace nhdyn_test {
class scratch_folder {
 public:
  explicit scratch_folder(const std::string& name)
      : path_(std::filesystem::temp_directory_path() / ("nhdyn_test_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  scratch_folder(const scratch_folder&) = delete;
  scratch_folder& operator=(const scratch_folder&) = delete;
  ~scratch_folder() {
    const char* keep = std::getenv("NHDYN_KEEP_TEST_FILES");
    if (keep != nullptr && *keep != '\0' && std::string(keep) != "0") {
      std::fprintf(stderr, "NHDYN_KEEP_TEST_FILES: kept %s\n", path_.string().c_str());
      return;
    }
    std::error_code ec;  // a destructor at exit: a folder that cannot be removed stays
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// One folder per name and program (a test group's files share one program, each with its name).
inline const std::filesystem::path& scratch_dir(const std::string& name) {
  static std::map<std::string, scratch_folder> folders;
  return folders.try_emplace(name, name).first->second.path();
}
}  // namespace nhdyn_test
