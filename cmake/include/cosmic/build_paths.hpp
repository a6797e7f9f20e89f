// Paths of this build tree and checkout, for the programs that need them (tests, cosmicctl in its
// build tree). A program defines those it uses through cosmic_build_paths() in CMake
// (cmake/build_paths.cmake); naming one it did not define fails at link time.
#pragma once

namespace cosmic::build_paths {

extern const char* const source_dir;           // the checkout's top directory
extern const char* const bad_config_dir;       // tests/unit/bad_configs
extern const char* const dbc_dir;              // tests/unit/dbc
extern const char* const dds_peer;             // the cosmic-dds-peer program
extern const char* const lcm_peer;             // the cosmic-lcm-peer program
extern const char* const lcm_logger;           // Debian's lcm-logger ("" when not installed)
extern const char* const client_config_dir;    // the build tree's cosmic_client CMake package
extern const char* const cosmicctl_build_dir;  // where cosmicctl is built
extern const char* const fmi_test_model;       // the shared library of the tests' FMUs (tests/unit/fmi)
extern const char* const test_fmu_dir;  // the test FMUs built from tests/fmi_models: NAME-fmi2.fmu, NAME-fmi3.fmu

}  // namespace cosmic::build_paths
