# Installing slideid (`cmake --install build --prefix P`, docs/install.md, "CMake package"): the
# libraries, their headers under P/include/slideid (included as "estimator/estimate.h"), the
# tools, the scenes and the bundled log, and a CMake package, so that another project can
#   find_package(slideid REQUIRED)
#   target_link_libraries(app PRIVATE slideid::estimator)
# The Python module installs itself (python/CMakeLists.txt).
include(CMakePackageConfigHelpers)

set(SLIDEID_INSTALL_INCLUDEDIR "${CMAKE_INSTALL_INCLUDEDIR}/slideid")
set(SLIDEID_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/slideid")
set_property(GLOBAL PROPERTY SLIDEID_ROOMS "")

# Makes the library `target` of the folder `room` installable and exports it as
# slideid::<room> (also an alias in this tree): its headers are found as "<room>/x.h" in the
# source tree and in the installed include/slideid.
function(slideid_library_room target room)
  get_target_property(type ${target} TYPE)
  set(scope PUBLIC)
  if(type STREQUAL "INTERFACE_LIBRARY")
    set(scope INTERFACE)
  endif()
  target_include_directories(${target} ${scope}
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
    $<INSTALL_INTERFACE:${SLIDEID_INSTALL_INCLUDEDIR}>)
  target_compile_features(${target} ${scope} cxx_std_17)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${room})
  add_library(slideid::${room} ALIAS ${target})
  install(TARGETS ${target} EXPORT slideidTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  file(GLOB headers CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/${room}/*.h)
  install(FILES ${headers} DESTINATION ${SLIDEID_INSTALL_INCLUDEDIR}/${room})
  set_property(GLOBAL APPEND PROPERTY SLIDEID_ROOMS ${room})
endfunction()

# The package files, once every library and tool is declared.
function(slideid_install_package)
  get_property(tools GLOBAL PROPERTY SLIDEID_TOOL_TARGETS)
  install(TARGETS ${tools} EXPORT slideidTargets RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(EXPORT slideidTargets NAMESPACE slideid:: FILE slideidTargets.cmake
          DESTINATION ${SLIDEID_INSTALL_CMAKEDIR})
  get_property(SLIDEID_ROOMS GLOBAL PROPERTY SLIDEID_ROOMS)
  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/slideidConfig.cmake.in
    ${PROJECT_BINARY_DIR}/slideidConfig.cmake INSTALL_DESTINATION ${SLIDEID_INSTALL_CMAKEDIR})
  # 0.x: a minor version may change the API.
  write_basic_package_version_file(${PROJECT_BINARY_DIR}/slideidConfigVersion.cmake
    VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
  install(FILES ${PROJECT_BINARY_DIR}/slideidConfig.cmake
                ${PROJECT_BINARY_DIR}/slideidConfigVersion.cmake
                ${PROJECT_SOURCE_DIR}/cmake/FindRosbagStorage.cmake
                ${PROJECT_SOURCE_DIR}/cmake/FindLZ4.cmake
          DESTINATION ${SLIDEID_INSTALL_CMAKEDIR})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/datasets/scenes
          DESTINATION ${CMAKE_INSTALL_DATADIR}/slideid)
  install(FILES ${PROJECT_SOURCE_DIR}/datasets/logs/default_push.csv
          DESTINATION ${CMAKE_INSTALL_DATADIR}/slideid/logs)
endfunction()
