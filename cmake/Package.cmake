# Install rules and the two ways to consume the installed library:
#   CMake:      find_package(rthdist [COMPONENTS io masks]) -> rthdist::rthdist, rthdist::io,
#               rthdist::masks (static builds)
#   pkg-config: rthdist.pc, rthdist-io.pc
# Static builds also install the internal layers librthdist.a needs
# (librthdist_core.a, _cpu.a, _gpu.a, _gpu_algo.a; exported as rthdist::core,
# ... for the link line only, not meant to be linked directly).
include(CMakePackageConfigHelpers)
set(RTHDIST_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/rthdist)

# 0.x: every minor release may change the ABI.
set_target_properties(rthdist rthdist_io PROPERTIES
  VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
set_target_properties(rthdist_io PROPERTIES EXPORT_NAME io)
foreach(layer IN LISTS RTHDIST_INTERNAL_LAYERS)
  string(REGEX REPLACE "^rthdist_" "" name ${layer})
  set_target_properties(${layer} PROPERTIES EXPORT_NAME ${name})
endforeach()

set(core_targets rthdist)
if(NOT BUILD_SHARED_LIBS)
  list(APPEND core_targets ${RTHDIST_INTERNAL_LAYERS})
endif()
install(TARGETS ${core_targets} EXPORT rthdistTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS rthdist_io EXPORT rthdistIoTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# The masks component (static builds): rthdist::masks and the two archives it links.
if(TARGET rthdist_masks_core AND NOT BUILD_SHARED_LIBS)
  set_target_properties(rthdist_masks_core PROPERTIES EXPORT_NAME masks)
  set_target_properties(rthdist_masks_volumes PROPERTIES EXPORT_NAME masks_volumes)
  set_target_properties(rthdist_masks_gpu PROPERTIES EXPORT_NAME masks_gpu)
  install(TARGETS rthdist_masks_core rthdist_masks_volumes rthdist_masks_gpu EXPORT rthdistMasksTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(EXPORT rthdistMasksTargets NAMESPACE rthdist:: DESTINATION ${RTHDIST_CMAKE_DIR})
endif()
install(DIRECTORY include/rthdist ${RTHDIST_GENERATED_INCLUDE}/rthdist DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT rthdistTargets NAMESPACE rthdist:: DESTINATION ${RTHDIST_CMAKE_DIR})
install(EXPORT rthdistIoTargets NAMESPACE rthdist:: DESTINATION ${RTHDIST_CMAKE_DIR})

configure_package_config_file(cmake/rthdistConfig.cmake.in ${PROJECT_BINARY_DIR}/rthdistConfig.cmake
  INSTALL_DESTINATION ${RTHDIST_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/rthdistConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/rthdistConfig.cmake ${PROJECT_BINARY_DIR}/rthdistConfigVersion.cmake
  DESTINATION ${RTHDIST_CMAKE_DIR})

# pkg-config: relocatable (prefix from the .pc file's own place), so
# `cmake --install build --prefix DIR` gives a working DIR/lib/pkgconfig.
# A static library lists what it needs under Requires/Libs (plain
# `pkg-config --libs` links it); a shared one under the .private fields.
set(RTHDIST_PC_DIR ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
  set(RTHDIST_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
else()
  file(RELATIVE_PATH rel "/${RTHDIST_PC_DIR}" "/")
  string(REGEX REPLACE "/$" "" rel "${rel}")
  set(RTHDIST_PC_PREFIX "\${pcfiledir}/${rel}")
endif()
if(BUILD_SHARED_LIBS)
  set(RTHDIST_PC_REQUIRES "glm")
  set(RTHDIST_PC_REQUIRES_PRIVATE "vulkan")
  set(RTHDIST_PC_LIBS "-lrthdist")
  set(RTHDIST_PC_LIBS_PRIVATE "-lpthread")
  set(RTHDIST_IO_PC_REQUIRES "glm")
  set(RTHDIST_IO_PC_REQUIRES_PRIVATE "zlib libdeflate liblzf")
else()
  set(RTHDIST_PC_REQUIRES "glm vulkan")
  set(RTHDIST_PC_REQUIRES_PRIVATE "")
  set(RTHDIST_PC_LIBS "-lrthdist -lrthdist_gpu_algo -lrthdist_gpu -lrthdist_cpu -lrthdist_core -lpthread")
  set(RTHDIST_PC_LIBS_PRIVATE "")
  set(RTHDIST_IO_PC_REQUIRES "glm zlib libdeflate liblzf")
  set(RTHDIST_IO_PC_REQUIRES_PRIVATE "")
endif()
configure_file(cmake/rthdist.pc.in ${PROJECT_BINARY_DIR}/rthdist.pc @ONLY)
configure_file(cmake/rthdist-io.pc.in ${PROJECT_BINARY_DIR}/rthdist-io.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/rthdist.pc ${PROJECT_BINARY_DIR}/rthdist-io.pc DESTINATION ${RTHDIST_PC_DIR})
