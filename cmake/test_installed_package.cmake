# ctest: installs the build into a fresh prefix, configures examples/library against it with
# find_package(antpose), builds it and runs it on the bundled contact capture (cmake -P, with
# BUILD_DIR, SOURCE_DIR, WORK_DIR and GENERATOR).
file(REMOVE_RECURSE "${WORK_DIR}")
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${ARGN}\nfailed (${status}):\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()
run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix")
foreach(file include/antpose/version.hpp include/antpose/measure/contact.hpp lib/cmake/antpose/antposeConfig.cmake
             lib/cmake/antpose/antposeConfigVersion.cmake bin/antpose)
  if(NOT EXISTS "${WORK_DIR}/prefix/${file}")
    message(FATAL_ERROR "the installed package has no ${file}")
  endif()
endforeach()
run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/examples/library" -B "${WORK_DIR}/build" -G "${GENERATOR}"
    -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix")
run(${CMAKE_COMMAND} --build "${WORK_DIR}/build")
run("${WORK_DIR}/build/contact_attitude" "${SOURCE_DIR}/examples/contact-sample")
if(NOT out MATCHES "downtilt [0-9.-]+ ± [0-9.]+ deg")
  message(FATAL_ERROR "contact_attitude printed no downtilt:\n${out}")
endif()
message(STATUS "${out}")
file(REMOVE_RECURSE "${WORK_DIR}")
