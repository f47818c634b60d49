#include "sim/mujoco_model.h"

#include <cstring>
#include <mutex>

#include "common/check.h"

namespace roamlab::sim {
namespace {

thread_local std::vector<std::string> warnings;

[[noreturn]] void ThrowError(const char* message) { throw MujocoError(message); }

void CollectWarning(const char* message) { warnings.emplace_back(message); }

// MuJoCo's messages span lines ("Error: ...\nElement 'x', line 3"); a Status message is one line.
std::string OneLine(std::string text) {
  for (char& c : text)
    if (c == '\n' || c == '\r') c = ' ';
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

struct VfsDeleter {
  void operator()(mjVFS* vfs) const {
    mj_deleteVFS(vfs);
    delete vfs;
  }
};

}  // namespace

void InstallMujocoHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = ThrowError;
    mju_user_warning = CollectWarning;
  });
}

std::vector<std::string> TakeMujocoWarnings() {
  std::vector<std::string> out;
  out.swap(warnings);
  return out;
}

Result<ModelPtr> LoadModelFromFiles(const std::string& main, const std::map<std::string, std::string>& files,
                                    const std::string& what) {
  InstallMujocoHandlers();
  // The VFS is about 2 MB: on the heap.
  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);
  mj_defaultVFS(vfs.get());
  for (const auto& [name, content] : files) {
    if (mj_makeEmptyFileVFS(vfs.get(), name.c_str(), static_cast<int>(content.size())) != 0)
      return Status::Error(what + ": cannot add '" + name + "' to the MuJoCo virtual file system");
    const int index = mj_findFileVFS(vfs.get(), name.c_str());
    ROAMLAB_CHECK(index >= 0, "VFS lost " << name);
    std::memcpy(vfs->filedata[index], content.data(), content.size());
  }
  char error[1024] = "";
  mjModel* model = nullptr;
  try {
    model = mj_loadXML(main.c_str(), vfs.get(), error, sizeof error);
  } catch (const MujocoError& e) {
    return Status::Error(what + ": MuJoCo: " + OneLine(e.what()));
  }
  if (model == nullptr) return Status::Error(what + ": MuJoCo: " + OneLine(error));
  return ModelPtr(model);
}

Result<ModelPtr> LoadModelFromString(const std::string& xml, const std::string& what) {
  return LoadModelFromFiles("model.xml", {{"model.xml", xml}}, what);
}

DataPtr MakeData(const mjModel* model) {
  InstallMujocoHandlers();
  mjData* data = mj_makeData(model);
  ROAMLAB_CHECK(data != nullptr, "mj_makeData failed");
  return DataPtr(data);
}

int IdOf(const mjModel* model, mjtObj type, const std::string& name) { return mj_name2id(model, type, name.c_str()); }

}  // namespace roamlab::sim
