// MuJoCo 2.2.2 glue for the simulator: error and warning handlers, owning pointers, and models compiled from text held
// in memory (2.2.2 has no load-from-string: the text goes through a heap-allocated mjVFS).
//
// Handlers: MuJoCo's default error handler prints "Press Enter to exit", blocks on stdin and writes
// MUJOCO_LOG.TXT. InstallMujocoHandlers() replaces it with one that throws MujocoError (a C++ exception passes through
// MuJoCo's C frames), and replaces the warning handler with one that appends the message to a per-thread list that
// TakeMujocoWarnings() returns. Every function here installs them first; it is idempotent and thread-safe.
#pragma once

#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include "common/status.h"

namespace roamlab::sim {

// What the installed error handler throws; what() is MuJoCo's message.
class MujocoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void InstallMujocoHandlers();
// The warnings MuJoCo reported on this thread since the last call, oldest first; clears the list.
std::vector<std::string> TakeMujocoWarnings();

struct ModelDeleter {
  void operator()(mjModel* model) const { mj_deleteModel(model); }
};
struct DataDeleter {
  void operator()(mjData* data) const { mj_deleteData(data); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

// Compiles an MJCF model whose files are all given as text: `files` maps file names (as written in <include file=...>)
// to their content, `main` names the top-level one. Errors: "<what>: MuJoCo: <compiler message on one line>", where
// `what` names the source for the user (e.g. the model file path).
Result<ModelPtr> LoadModelFromFiles(const std::string& main, const std::map<std::string, std::string>& files,
                                    const std::string& what);
// One self-contained MJCF document.
Result<ModelPtr> LoadModelFromString(const std::string& xml, const std::string& what = "inline MJCF");

// mj_makeData, checked.
DataPtr MakeData(const mjModel* model);

// Id of a named element or -1 (mj_name2id).
int IdOf(const mjModel* model, mjtObj type, const std::string& name);

}  // namespace roamlab::sim
