# libvdbdag: the public reader library (include/vdbdag/vdbdag.h), a shared
# library whose only dependencies are the C++ standard library, zstd and
# xxHash; installed with a CMake package (find_package(vdbdag CONFIG) ->
# vdbdag::vdbdag) and a pkg-config file (vdbdag.pc).
#
# It is built from the sources of the reading path only (compiled again,
# position-independent); everything else of the core stays out of it, which
# the link checks (-Wl,--no-undefined).
set(VDBDAG_READER_SOURCES
    src/reader/Accessor.cpp src/reader/File.cpp
    src/format/ByteIO.cpp src/format/DagBounds.cpp src/format/ReadLimits.cpp src/format/SsvdagContainer.cpp
    src/format/SsvdagFile.cpp src/format/ValueReference.cpp src/format/FrameSequence.cpp src/format/ZstdFrame.cpp
    src/encoding/AttributeLayout.cpp src/encoding/CompactDag.cpp src/encoding/DagStructure.cpp
    src/attributes/NormalChannel.cpp src/attributes/OctahedralNormal.cpp src/attributes/PaletteChannel.cpp
    src/attributes/ContextChannel.cpp src/attributes/PredictedChannel.cpp src/attributes/PredictedWindows.cpp src/attributes/RescaledFloats.cpp src/coding/BrickValueCoder.cpp src/coding/LeastSquaresKernels.cpp src/coding/FloatValueCoder.cpp src/coding/FloatIntegerCoder.cpp src/coding/LabelCoder.cpp
    src/attributes/ValueWindows.cpp src/attributes/WindowCursor.cpp
    src/volume/GridRecord.cpp src/volume/GridTopology.cpp src/volume/SignedFill.cpp src/format/InactiveSignedFill.cpp
    src/dag/DagBuilder.cpp src/dag/LevelBuilder.cpp
    src/util/InputPath.cpp src/util/ScratchFile.cpp src/util/TemporaryFiles.cpp)
add_library(vdbdag_lib SHARED ${VDBDAG_READER_SOURCES})
target_include_directories(vdbdag_lib
  PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
  PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
target_link_libraries(vdbdag_lib PRIVATE zstd::libzstd_shared PkgConfig::XXHASH)
target_link_options(vdbdag_lib PRIVATE -Wl,--no-undefined -Wl,--as-needed)
if(CMAKE_SYSTEM_PROCESSOR MATCHES "x86_64|AMD64")
  target_compile_options(vdbdag_lib PRIVATE -mpopcnt)
endif()
set_target_properties(vdbdag_lib PROPERTIES OUTPUT_NAME vdbdag EXPORT_NAME vdbdag
  VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR}
  CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
target_compile_definitions(vdbdag_lib PRIVATE VDBDAG_BUILDING_LIBRARY)
add_library(vdbdag::vdbdag ALIAS vdbdag_lib)

include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
install(TARGETS vdbdag_lib EXPORT vdbdagTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# The accessor headers that compile as C++ and as GLSL go with it, so that
# another program's shaders can walk a .ssvdag as ours do (the PNanoVDB way).
install(FILES include/vdbdag/vdbdag.h include/vdbdag/Error.h include/vdbdag/shader_lang.h include/vdbdag/dag_access.h
              include/vdbdag/palette_access.h include/vdbdag/normal_access.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vdbdag)
install(EXPORT vdbdagTargets NAMESPACE vdbdag:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/vdbdag)
configure_package_config_file(${CMAKE_CURRENT_SOURCE_DIR}/cmake/vdbdagConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/vdbdagConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/vdbdag)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/vdbdagConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/vdbdagConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/vdbdagConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/vdbdag)
configure_file(${CMAKE_CURRENT_SOURCE_DIR}/cmake/vdbdag.pc.in ${CMAKE_CURRENT_BINARY_DIR}/vdbdag.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/vdbdag.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
# The same package for projects built against this build tree (the
# ParaView plugin, cmake/ParaViewPlugin.cmake): -Dvdbdag_DIR=BUILD/reader-config.
export(EXPORT vdbdagTargets NAMESPACE vdbdag:: FILE ${CMAKE_CURRENT_BINARY_DIR}/reader-config/vdbdagTargets.cmake)
file(COPY ${CMAKE_CURRENT_BINARY_DIR}/vdbdagConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/vdbdagConfigVersion.cmake
     DESTINATION ${CMAKE_CURRENT_BINARY_DIR}/reader-config)
