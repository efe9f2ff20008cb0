# The installed CMake package, as another project uses it: installs the build BUILD_DIR into
# a fresh prefix under WORK_DIR, configures, builds and runs the consumer project
# (SOURCE_DIR) against it, and checks that the package version is the installed tools'
# --version. With PYTHON (and PYTHON_DIR, relative to the prefix), also imports the
# installed Python module. Nothing is downloaded. Run by ctest (tests/CMakeLists.txt):
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... [-DPYTHON=... -DPYTHON_DIR=...]
#         -P run_consumer_test.cmake
foreach(var BUILD_DIR SOURCE_DIR WORK_DIR GENERATOR CXX)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "run_consumer_test.cmake: -D${var}=... is required")
  endif()
endforeach()

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "${what} failed (${code}):\n${out}\n${err}")
  endif()
  set(output "${out}" PARENT_SCOPE)
endfunction()

set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})
run("install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(file include/slideid/estimator/estimate.h lib/cmake/slideid/slideidConfig.cmake
             lib/cmake/slideid/slideidConfigVersion.cmake bin/identify)
  if(NOT EXISTS ${prefix}/${file})
    message(FATAL_ERROR "the install has no ${file}")
  endif()
endforeach()

# The installed headers are the public API: none may include Ceres or a library's internal/
# headers (those stay in the source tree, as Ceres keeps its own internal/ out of its
# install), and no internal/ folder is installed.
file(GLOB_RECURSE installed_headers ${prefix}/include/slideid/*.h)
foreach(header ${installed_headers})
  file(STRINGS ${header} includes REGEX "^#include")
  foreach(line ${includes})
    if(line MATCHES "<ceres/|internal/")
      message(FATAL_ERROR "installed header ${header} exposes an internal: ${line}")
    endif()
  endforeach()
  if(header MATCHES "/internal/")
    message(FATAL_ERROR "an internal header is installed: ${header}")
  endif()
endforeach()

# Only the fresh prefix may provide slideid: no package registry, no source tree.
run("configuring the consumer" ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build
    -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
run("building the consumer" ${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run("running the consumer" ${WORK_DIR}/build/consumer)
message(STATUS "consumer: ${output}")
if(NOT output MATCHES "slideid ([0-9.]+): ok")
  message(FATAL_ERROR "the consumer did not report its package version")
endif()
set(package_version ${CMAKE_MATCH_1})

run("identify --version" ${prefix}/bin/identify --version)
if(NOT output STREQUAL "identify (slideid) ${package_version}\n")
  message(FATAL_ERROR "package version ${package_version}, but identify --version says: ${output}")
endif()

if(DEFINED PYTHON)
  run("importing the installed Python module" ${CMAKE_COMMAND} -E env
      PYTHONPATH=${prefix}/${PYTHON_DIR} PYTHONDONTWRITEBYTECODE=1
      ${PYTHON} -c "print(__import__('slideid').__version__, __import__('slideid').__file__)")
  if(NOT output MATCHES "^${package_version} ${prefix}/")
    message(FATAL_ERROR "the installed Python module: ${output}")
  endif()
endif()
message(STATUS "the installed package ${package_version} works from ${prefix}")
