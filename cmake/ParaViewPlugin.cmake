# The ParaView reader plugin (paraview/), built when Debian's paraview-dev is
# installed. It is compiled against ParaView's own VTK, whose imported
# targets clash with the system VTK that vdb_bridge links, so it is a project
# of its own, run as an external project over the reader library of this
# build tree (reader-config/). Its SDK is a view of /usr made by
# scripts/paraview_sdk.sh (why: that script's comment). Results:
#   build/paraview/lib/paraview-5.11/plugins/VdbdagReader/VdbdagReader.so
#     (ParaView: Tools > Manage Plugins > Load New, or PV_PLUGIN_PATH)
#   cmake --install: LIBDIR/paraview-5.11/plugins/VdbdagReader/ (ParaView's layout)
# VDBDAG_PARAVIEW_PLUGIN is the plugin's path in the build tree when built,
# VDBDAG_PARAVIEW_PREFIX the SDK's prefix (bin/pvpython, lib/python3/dist-packages).
option(VDBDAG_PARAVIEW "Build the ParaView plugin when paraview-dev is installed" ON)
set(VDBDAG_PARAVIEW_PLUGIN "")
if(VDBDAG_PARAVIEW)
  if(NOT VDBDAG_PARAVIEW_DIR)
    execute_process(COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/scripts/paraview_sdk.sh
                    OUTPUT_VARIABLE _vdbdag_pv_dir OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE _vdbdag_pv_result)
    if(_vdbdag_pv_result EQUAL 0 AND EXISTS "${_vdbdag_pv_dir}/paraview-config.cmake")
      set(VDBDAG_PARAVIEW_DIR "${_vdbdag_pv_dir}" CACHE PATH "ParaView's CMake package for the plugin (scripts/paraview_sdk.sh)")
    endif()
  endif()
  if(VDBDAG_PARAVIEW_DIR AND EXISTS "${VDBDAG_PARAVIEW_DIR}/paraview-config.cmake")
    # The checked .vdb reading of vdb_bridge (the file's layout verified
    # before OpenVDB walks it, grids in file order), position-independent
    # for the plugin, which links it through reader-config/.
    add_library(vdbdag_vdb_files STATIC vdb_bridge/detail/VdbFile.cpp vdb_bridge/detail/VdbFileLayout.cpp
                src/util/AtomicFile.cpp src/util/InputPath.cpp src/util/TemporaryFiles.cpp)
    set_target_properties(vdbdag_vdb_files PROPERTIES POSITION_INDEPENDENT_CODE ON)
    target_include_directories(vdbdag_vdb_files PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}>)
    target_link_libraries(vdbdag_vdb_files PUBLIC OpenVDB::openvdb)
    export(TARGETS vdbdag_vdb_files NAMESPACE vdbdag:: FILE ${CMAKE_CURRENT_BINARY_DIR}/reader-config/vdbdagVdbFilesTargets.cmake)
    string(REGEX MATCH "paraview-[0-9]+\\.[0-9]+$" _vdbdag_pv_subdir "${VDBDAG_PARAVIEW_DIR}")
    include(ExternalProject)
    ExternalProject_Add(vdbdag_paraview
      SOURCE_DIR ${CMAKE_CURRENT_SOURCE_DIR}/paraview
      BINARY_DIR ${CMAKE_CURRENT_BINARY_DIR}/paraview
      CMAKE_ARGS -DCMAKE_BUILD_TYPE=${CMAKE_BUILD_TYPE} -DCMAKE_CXX_COMPILER=${CMAKE_CXX_COMPILER}
                 -DParaView_DIR=${VDBDAG_PARAVIEW_DIR} -Dvdbdag_DIR=${CMAKE_CURRENT_BINARY_DIR}/reader-config
      CMAKE_CACHE_ARGS -DCMAKE_CXX_COMPILER_LAUNCHER:STRING=${CMAKE_CXX_COMPILER_LAUNCHER}  # the compiler cache, if any
      BUILD_ALWAYS ON
      INSTALL_COMMAND ""
      DEPENDS vdbdag_lib vdbdag_vdb_files)
    set(VDBDAG_PARAVIEW_PLUGIN ${CMAKE_CURRENT_BINARY_DIR}/paraview/lib/${_vdbdag_pv_subdir}/plugins/VdbdagReader/VdbdagReader.so)
    # pvpython and ParaView's Python modules, for the plugin's test.
    get_filename_component(VDBDAG_PARAVIEW_PREFIX "${VDBDAG_PARAVIEW_DIR}/../../../.." ABSOLUTE)
    install(CODE "execute_process(COMMAND \"${CMAKE_COMMAND}\" --install \"${CMAKE_CURRENT_BINARY_DIR}/paraview\" --prefix \"\${CMAKE_INSTALL_PREFIX}\"
                                  RESULT_VARIABLE result)
                  if(result)
                    message(FATAL_ERROR \"installing the ParaView plugin failed\")
                  endif()")
    message(STATUS "ParaView plugin: built against ${VDBDAG_PARAVIEW_DIR}")
  else()
    message(STATUS "ParaView plugin: not built (no paraview-dev; scripts/setup.sh installs it)")
  endif()
endif()
