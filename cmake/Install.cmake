# Installs the validation library (and the renderer it builds on) with its
# headers and an exported CMake package, so users link rayaudit::validation.
#   find_package(rayaudit REQUIRED)
#   target_link_libraries(my_tests PRIVATE rayaudit::validation GTest::gtest_main)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(RAYAUDIT_INCLUDE_INSTALL_DIR ${CMAKE_INSTALL_INCLUDEDIR}/rayaudit)
target_include_directories(rayaudit_renderer PUBLIC $<INSTALL_INTERFACE:${RAYAUDIT_INCLUDE_INSTALL_DIR}>)
target_include_directories(rayaudit_validation PUBLIC $<INSTALL_INTERFACE:${RAYAUDIT_INCLUDE_INSTALL_DIR}>)
set_target_properties(rayaudit_renderer PROPERTIES EXPORT_NAME renderer)
set_target_properties(rayaudit_validation PROPERTIES EXPORT_NAME validation)

install(TARGETS rayaudit_renderer rayaudit_validation EXPORT rayauditTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
file(GLOB _renderer_headers ${PROJECT_SOURCE_DIR}/renderer/*.h)
file(GLOB _method_headers ${PROJECT_SOURCE_DIR}/renderer/methods/*.h)
file(GLOB _validation_headers ${PROJECT_SOURCE_DIR}/validation/*.h)
install(FILES ${_renderer_headers} ${_validation_headers} DESTINATION ${RAYAUDIT_INCLUDE_INSTALL_DIR})
install(FILES ${_method_headers} DESTINATION ${RAYAUDIT_INCLUDE_INSTALL_DIR}/methods)

set(RAYAUDIT_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/rayaudit)
install(EXPORT rayauditTargets NAMESPACE rayaudit:: DESTINATION ${RAYAUDIT_CMAKE_DIR})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/rayauditConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/rayauditConfig.cmake INSTALL_DESTINATION ${RAYAUDIT_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/rayauditConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/rayauditConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/rayauditConfigVersion.cmake
        DESTINATION ${RAYAUDIT_CMAKE_DIR})
