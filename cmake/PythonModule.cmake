# The Python package `vdbdag` (python/): the reader through pybind11
# (vdbdag._vdbdag, linked to libvdbdag) and encode/decode in-process
# (vdbdag._codec, linked to the command's libraries). Built when pybind11 and Python's headers are found; usable from
# the build tree with PYTHONPATH=build/python, installed under
# lib/python3/dist-packages (Debian's layout).
#
# The interpreter is Debian's (/usr/bin/python3) unless Python3_EXECUTABLE
# says otherwise: Debian's pybind11, numpy, pytest and pyopenvdb are
# installed for it, not for a pyenv or virtualenv python earlier on the PATH.
if(NOT Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python3_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "Python for the vdbdag module and its tests")
endif()
find_package(Python3 COMPONENTS Interpreter Development.Module)
find_package(pybind11 CONFIG QUIET)
if(Python3_FOUND AND pybind11_FOUND)
  set(VDBDAG_PYTHON_DIR ${CMAKE_CURRENT_BINARY_DIR}/python/vdbdag)
  pybind11_add_module(vdbdag_python MODULE python/module.cpp)
  target_link_libraries(vdbdag_python PRIVATE vdbdag_lib)
  set_target_properties(vdbdag_python PROPERTIES OUTPUT_NAME _vdbdag LIBRARY_OUTPUT_DIRECTORY ${VDBDAG_PYTHON_DIR}
                        INSTALL_RPATH "$ORIGIN/../../..")
  # vdbdag._codec: encode and decode in this process, through the library
  # the command calls (app/); loaded on the first encode or decode, since it
  # brings OpenVDB and GDCM.
  pybind11_add_module(vdbdag_python_codec MODULE python/codec_module.cpp)
  target_link_libraries(vdbdag_python_codec PRIVATE vdbdag_app vdbdag_bridge_dicom vdbdag_bridge vdbdag_core)
  set_target_properties(vdbdag_python_codec PROPERTIES OUTPUT_NAME _codec LIBRARY_OUTPUT_DIRECTORY ${VDBDAG_PYTHON_DIR})
  configure_file(python/vdbdag/__init__.py ${VDBDAG_PYTHON_DIR}/__init__.py COPYONLY)
  set(VDBDAG_PYTHON_INSTALL_DIR ${CMAKE_INSTALL_LIBDIR}/python3/dist-packages/vdbdag)
  install(TARGETS vdbdag_python vdbdag_python_codec LIBRARY DESTINATION ${VDBDAG_PYTHON_INSTALL_DIR})
  install(FILES python/vdbdag/__init__.py DESTINATION ${VDBDAG_PYTHON_INSTALL_DIR})
  set(VDBDAG_HAVE_PYTHON ON)
else()
  message(STATUS "vdbdag: pybind11 or Python's headers not found, the Python module is not built")
endif()
