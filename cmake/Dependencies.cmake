# Finds every dependency with find_package; when one is absent, stops with a
# message naming the Debian package that provides it (ci/install-deps.sh
# installs them all).
macro(rayaudit_require pkg debian)
  find_package(${pkg} ${ARGN} QUIET)
  if(NOT ${pkg}_FOUND)
    message(FATAL_ERROR
      "rayaudit needs ${pkg}: install the Debian package '${debian}' "
      "(or run ci/install-deps.sh, which installs everything missing).")
  endif()
endmacro()

rayaudit_require(Threads libc6-dev)
rayaudit_require(nlohmann_json nlohmann-json3-dev)
rayaudit_require(CLI11 libcli11-dev)
rayaudit_require(OpenImageIO libopenimageio-dev CONFIG)
rayaudit_require(GTest libgtest-dev)
rayaudit_require(CGAL libcgal-dev)
rayaudit_require(tinyobjloader libtinyobjloader-dev)
rayaudit_require(embree libembree-dev 3)
if(RAYAUDIT_BUILD_BENCH)
  rayaudit_require(benchmark libbenchmark-dev)
endif()

find_program(POVRAY_EXECUTABLE povray)
if(NOT POVRAY_EXECUTABLE)
  message(FATAL_ERROR "rayaudit needs POV-Ray 3.7: install the Debian package 'povray'.")
endif()
find_program(OIIOTOOL_EXECUTABLE oiiotool)
if(NOT OIIOTOOL_EXECUTABLE)
  message(FATAL_ERROR "rayaudit needs oiiotool: install the Debian package 'openimageio-tools'.")
endif()

# Debian 12's OpenImageIO config lists /usr/include/opencv4 among its include
# directories although OIIO's headers never need OpenCV; drop what does not
# exist rather than install OpenCV's headers.
foreach(_oiio_target OpenImageIO::OpenImageIO OpenImageIO::OpenImageIO_Util)
  if(TARGET ${_oiio_target})
    get_target_property(_dirs ${_oiio_target} INTERFACE_INCLUDE_DIRECTORIES)
    if(_dirs)
      set(_kept "")
      foreach(_d ${_dirs})
        if(EXISTS "${_d}" OR _d MATCHES "^\\$<")
          list(APPEND _kept "${_d}")
        endif()
      endforeach()
      set_target_properties(${_oiio_target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_kept}")
    endif()
  endif()
endforeach()
