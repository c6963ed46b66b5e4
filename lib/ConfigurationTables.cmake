# The configuration tables of paper §5.1, generated at build time from Definition 9:
# surftrack_generate_tables computes them (LocalConvexVolume.cpp) and writes
# ${CMAKE_BINARY_DIR}/generated/ConfigurationTables.inc, #included by ConfigurationTable.cpp.
set(SURFTRACK_TABLES_DIR ${CMAKE_BINARY_DIR}/generated)
set(SURFTRACK_TABLES_INC ${SURFTRACK_TABLES_DIR}/ConfigurationTables.inc)

add_executable(surftrack_generate_tables
  ${CMAKE_CURRENT_LIST_DIR}/LocalConvexVolume.cpp
  ${PROJECT_SOURCE_DIR}/tools/generate_configuration_tables.cpp)
target_include_directories(surftrack_generate_tables PRIVATE ${CMAKE_CURRENT_LIST_DIR})

add_custom_command(
  OUTPUT ${SURFTRACK_TABLES_INC}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${SURFTRACK_TABLES_DIR}
  COMMAND surftrack_generate_tables ${SURFTRACK_TABLES_INC}
  DEPENDS surftrack_generate_tables
  COMMENT "Generating the configuration tables (Definition 9)"
  VERBATIM)

add_library(surftrack_tables STATIC
  ${CMAKE_CURRENT_LIST_DIR}/ConfigurationTable.cpp
  ${CMAKE_CURRENT_LIST_DIR}/LocalConvexVolume.cpp
  ${SURFTRACK_TABLES_INC})
target_include_directories(surftrack_tables
  PUBLIC ${CMAKE_CURRENT_LIST_DIR}
  PRIVATE ${SURFTRACK_TABLES_DIR})

target_link_libraries(surftrack_lib INTERFACE surftrack_tables)
