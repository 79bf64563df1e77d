# Public headers generated at configure time into the build tree and installed
# beside include/rthdist: rthdist/version.hpp (from project(VERSION)) and
# rthdist/export.hpp (RTHDIST_API / RTHDIST_IO_API for BUILD_SHARED_LIBS).
set(RTHDIST_GENERATED_INCLUDE ${PROJECT_BINARY_DIR}/include)
if(BUILD_SHARED_LIBS)
  set(RTHDIST_SHARED_01 1)
else()
  set(RTHDIST_SHARED_01 0)
endif()
configure_file(${PROJECT_SOURCE_DIR}/cmake/version.hpp.in ${RTHDIST_GENERATED_INCLUDE}/rthdist/version.hpp @ONLY)
configure_file(${PROJECT_SOURCE_DIR}/cmake/export.hpp.in ${RTHDIST_GENERATED_INCLUDE}/rthdist/export.hpp @ONLY)
