// Fuzzes the bag importer (importers/rosbag.h) on one container format: the input is the file's bytes, written to a
// scratch file with the extension ROAMLAB_FUZZ_BAG_EXTENSION (".bag": ROS 1, ".mcap": MCAP, ".db3": rosbag2 SQLite),
// then listed and imported with every supported topic.
#include "fuzz/fuzz_input.h"
#include "importers/rosbag.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = roamlab::fuzz::ScratchDirectory() + "/input" ROAMLAB_FUZZ_BAG_EXTENSION;
  roamlab::fuzz::WriteBytes(path, std::string_view(reinterpret_cast<const char*>(data), size));
  roamlab::fuzz::ExpectOneLineError(roamlab::importers::ListRosbag(path));
  roamlab::importers::RosbagImportOptions options;
  roamlab::importers::RosbagImportReport report;
  roamlab::fuzz::ExpectOneLineError(roamlab::importers::ImportRosbag(path, options, &report));
  return 0;
}
