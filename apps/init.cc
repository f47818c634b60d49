#include "apps/init.h"

#include <iostream>

#include "apps/cli.h"

namespace roamlab::apps {

int RunInit(const InitArgs& args) {
  experiment::InitConfig config;
  const experiment::Outcome outcome = experiment::InitToFile(args, &config);
  if (!outcome.ok()) return Exit(args.err, "init", outcome);
  if (args.quiet) return 0;
  std::size_t free = 0;
  for (const auto& [name, parameter] : config.config.parameters) free += parameter.free ? 1 : 0;
  std::cout << "wrote " << args.out << ": master '" << config.config.master << "' (platform " << config.platform_kind
            << "), " << config.config.streams.size() << " streams, " << free << " free parameters in "
            << config.config.stages.size() << " stages" << std::endl;
  for (const std::string& line : config.left_out) std::cout << "left out " << line << std::endl;
  return 0;
}

}  // namespace roamlab::apps
