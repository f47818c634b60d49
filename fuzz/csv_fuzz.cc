// Fuzzes the CSV importer (importers/csv.h): the input is the mapping YAML followed by the CSV files as parts
// "%%%% a.csv", "%%%% b.csv", ... (fuzz_input.h), passed in that order.
#include "fuzz/fuzz_input.h"
#include "importers/csv.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::vector<roamlab::fuzz::InputFile> files = roamlab::fuzz::SplitInput(data, size, "mapping.yaml");
  roamlab::fuzz::ResetScratch(files);
  const std::string directory = roamlab::fuzz::ScratchDirectory();
  std::vector<std::string> csv_files;
  for (const auto& file : files) {
    if (file.name != "mapping.yaml") csv_files.push_back(directory + "/" + file.name);
  }
  roamlab::importers::CsvImportReport report;
  roamlab::fuzz::ExpectOneLineError(roamlab::importers::ImportCsv(csv_files, directory + "/mapping.yaml", &report));
  return 0;
}
