#include <exception>
#include <filesystem>
#include <iostream>
#include <new>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "lucent/core/atomic_file.h"
#include "lucent/core/error.h"
#include "lucent/version.h"

int main(int argc, char** argv) {
  // First, before any thread starts: SIGINT/SIGTERM/SIGHUP remove this run's temporaries.
  lucent::remove_temporaries_on_signals();
  CLI::App app{
      "lucent: measure translucent materials and show them.\n"
      "Lengths in mm, coefficients in mm^-1 unless an option says otherwise.",
      "lucent"};
  app.set_version_flag("--version", std::string("lucent ") + lucent::kVersion);
  app.require_subcommand(1);
  app.fallthrough(false);
  lucent::cli::register_profile_command(app);
  lucent::cli::register_simulate_command(app);
  lucent::cli::register_acquire_command(app);
  lucent::cli::register_fit_command(app);
  lucent::cli::register_bench_command(app);
  lucent::cli::register_render_command(app);
  lucent::cli::register_view_command(app);
  lucent::cli::register_tabulate_command(app);
  lucent::cli::register_material_commands(app);
  lucent::cli::register_merge_command(app);
  lucent::cli::register_compare_command(app);
  lucent::cli::register_tonemap_command(app);
  // `lucent SUB --version` works as the README says, on every subcommand.
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
    sub->set_version_flag("--version", std::string("lucent ") + lucent::kVersion);

  // Every output of the command is committed together at the end, or none is (atomic_file.h).
  lucent::OutputTransaction outputs;

  try {
    app.parse(argc, argv);
    outputs.commit();
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, naming the option, instead of CLI11's two-line message.
    std::cerr << "lucent: error: " << lucent::printable(e.what()) << " (see lucent --help)\n";
    return 2;
  } catch (const lucent::Error& e) {
    std::cerr << "lucent: error: " << lucent::printable(e.what()) << '\n';
    return 1;
  } catch (const nlohmann::json::type_error& e) {
    // A name or path going into a JSON file that is not UTF-8 (nlohmann refuses to write it).
    if (e.id == 316) {
      std::cerr << "lucent: error: a name or file name going into a JSON file is not valid UTF-8 "
                   "(" << lucent::printable(e.what()) << "); nothing written\n";
      return 1;
    }
    std::cerr << "lucent: internal error: " << lucent::printable(e.what()) << '\n';
    return 3;
  } catch (const std::filesystem::filesystem_error& e) {
    // The file system refusing a path (a name longer than the file system allows, a folder that
    // is a file, no permission, a full disk): the user's path or machine to fix, not lucent's bug.
    std::cerr << "lucent: error: "
              << lucent::printable(e.path1().empty() ? std::string("a file") : e.path1().string())
              << ": " << lucent::printable(e.code().message()) << "; nothing written\n";
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << "lucent: error: out of memory (an input or a setting asks for more memory than "
                 "this machine has)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "lucent: internal error: " << lucent::printable(e.what()) << '\n';
    return 3;
  }
  return 0;
}
