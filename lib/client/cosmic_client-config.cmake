# The CMake package of libcosmic-client (package libcosmic-client-dev), for components:
#   find_package(cosmic_client CONFIG REQUIRED)
#   target_link_libraries(my_component PRIVATE cosmic::client)
# cosmic::client is the shared libcosmic-client.so.0 with the headers cosmic/client.h (C) and
# cosmic/client.hpp (C++20); Fast DDS and LCM come with the library, the component needs nothing else.
include("${CMAKE_CURRENT_LIST_DIR}/cosmic_client-targets.cmake")
