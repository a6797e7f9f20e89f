/* The shared library of the tests' FMUs (fmu_archive_test.cpp): what an FMU's binary exports first,
   its FMI version and types platform, so a test that loads the extracted library sees it is the one
   the build made. The runner's models (a plant, a controller) come with the runner. */
#define COSMIC_FMI_EXPORT __attribute__((visibility("default")))

COSMIC_FMI_EXPORT const char* fmi2GetVersion(void) { return "2.0"; }
COSMIC_FMI_EXPORT const char* fmi2GetTypesPlatform(void) { return "default"; }
COSMIC_FMI_EXPORT const char* fmi3GetVersion(void) { return "3.0"; }
