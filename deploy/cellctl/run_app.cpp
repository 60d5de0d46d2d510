#include "deploy/cellctl/run_app.hpp"

#include <iostream>

#include "deploy/cellctl/cell_config.hpp"
#include "twin/model/source_ref.hpp"

namespace cellctl {

namespace {

int fail(const std::exception& e, int code) {
  std::cerr << "error: " << e.what() << '\n';
  return code;
}

}  // namespace

int run_app(CLI::App& app, int argc, char** argv, const int& exit_code) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  } catch (const ConfigError& e) {
    return fail(e, 2);
  } catch (const twin::DescriptionError& e) {
    return fail(e, 2);
  } catch (const std::exception& e) {
    return fail(e, 1);
  }
  return exit_code;
}

}  // namespace cellctl
