// `cosmicctl check FILE`: offline admission of a configuration file.
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/knowledge_base.hpp"
#include "cosmic/report.hpp"

namespace cosmicctl {

CommandRunner add_check_command(CLI::App& app, const GlobalOptions& options) {
  auto* command = app.add_subcommand("check", "Validate a configuration and run admission offline");
  auto file = std::make_shared<std::string>();
  command->add_option("FILE", *file, "Configuration file (YAML)")->required();
  return [command, file, &options]() -> int {
    if (!command->parsed()) return -1;
    const auto loaded = cosmic::load_config_file(*file);
    if (!loaded.ok()) {
      if (options.json) {
        std::cout << nlohmann::json{{"errors", cosmic::to_json(loaded.errors)}}.dump(2) << "\n";
      } else {
        for (const auto& error : loaded.errors) std::cerr << error.to_string() << "\n";
        std::cerr << loaded.errors.size() << " error(s) in " << *file << "\n";
      }
      return kExitConfigError;
    }
    const auto report = cosmic::admit_all(loaded.config);
    if (options.json) {
      std::cout << cosmic::to_json(report).dump(2) << "\n";
    } else {
      std::cout << cosmic::render_text(report);
    }
    return report.any_rejected() ? kExitRejected : kExitOk;
  };
}

}  // namespace cosmicctl
