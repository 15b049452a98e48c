# Stable copies of the header-only build requirements (pybind11, Eigen).
#
# Why: `pip install .` builds in a fresh temporary environment every time
# (/tmp/pip-build-env-XXXX/overlay/...), and pybind11 and the cmeel-eigen wheel live there.
# Their include paths therefore change from one build to the next, so every compile command
# changes and every dependency file names headers that no longer exist: ninja recompiles the
# whole core although build-dir = "build/{wheel_tag}" is kept. Copying the headers into the
# build directory, with copy-if-different semantics (an unchanged file keeps its timestamp),
# makes the paths and the timestamps the same from build to build.
#
#   rigidfem_sync_tree(<source dir> <destination dir>)
#       Make <destination dir> hold the same files as <source dir>: copy new and changed
#       files, leave identical files untouched, delete files that are gone from the source.
#   rigidfem_find_pybind11()
#       find_package(pybind11) from a copy in ${CMAKE_BINARY_DIR}/deps/pybind11.
#   rigidfem_find_eigen()
#       The INTERFACE target rigidfem_eigen: the headers of a system Eigen 3.4 if there is one,
#       otherwise of the cmeel-eigen wheel, copied to ${CMAKE_BINARY_DIR}/deps/eigen3.

include_guard(GLOBAL)

set(RIGIDFEM_DEPS_DIR "${CMAKE_BINARY_DIR}/deps" CACHE INTERNAL
    "Stable copies of the header-only build requirements")

function(rigidfem_sync_tree source destination)
  file(GLOB_RECURSE wanted RELATIVE "${source}" "${source}/*")
  list(FILTER wanted EXCLUDE REGEX "(^|/)__pycache__/")
  set(present "")
  if(IS_DIRECTORY "${destination}")
    file(GLOB_RECURSE present RELATIVE "${destination}" "${destination}/*")
  endif()
  foreach(name IN LISTS wanted)
    if(CMAKE_VERSION VERSION_GREATER_EQUAL 3.21)
      get_filename_component(folder "${destination}/${name}" DIRECTORY)
      file(MAKE_DIRECTORY "${folder}")
      file(COPY_FILE "${source}/${name}" "${destination}/${name}" ONLY_IF_DIFFERENT)
    else()
      # Writes the output only when its content differs, too.
      configure_file("${source}/${name}" "${destination}/${name}" COPYONLY)
    endif()
  endforeach()
  if(present AND wanted)
    list(REMOVE_ITEM present ${wanted})
    foreach(name IN LISTS present)
      file(REMOVE "${destination}/${name}")
    endforeach()
  endif()
endfunction()

# Where a CMake package's configuration file lives, asked of the build's Python
# (the isolated build environment is on its sys.path).
function(_rigidfem_python_answer out code)
  execute_process(
    COMMAND "${Python_EXECUTABLE}" -c "${code}"
    OUTPUT_VARIABLE answer OUTPUT_STRIP_TRAILING_WHITESPACE
    RESULT_VARIABLE failed ERROR_QUIET)
  if(failed)
    set(answer "")
  endif()
  set(${out} "${answer}" PARENT_SCOPE)
endfunction()

macro(rigidfem_find_pybind11)
  _rigidfem_python_answer(_rigidfem_pybind11_cmake_dir
    "import pybind11; print(pybind11.get_cmake_dir())")
  if(_rigidfem_pybind11_cmake_dir AND EXISTS "${_rigidfem_pybind11_cmake_dir}/pybind11Config.cmake")
    # pybind11Config.cmake finds its headers at <config dir>/../../../include: copy the
    # headers and the configuration files to the same places under deps/pybind11.
    get_filename_component(_rigidfem_pybind11_prefix "${_rigidfem_pybind11_cmake_dir}/../../.." ABSOLUTE)
    file(RELATIVE_PATH _rigidfem_pybind11_rel "${_rigidfem_pybind11_prefix}" "${_rigidfem_pybind11_cmake_dir}")
    rigidfem_sync_tree("${_rigidfem_pybind11_prefix}/include/pybind11"
                       "${RIGIDFEM_DEPS_DIR}/pybind11/include/pybind11")
    rigidfem_sync_tree("${_rigidfem_pybind11_cmake_dir}"
                       "${RIGIDFEM_DEPS_DIR}/pybind11/${_rigidfem_pybind11_rel}")
    # FORCE: a pybind11_DIR cached by an earlier configure would win over PATHS.
    set(pybind11_DIR "${RIGIDFEM_DEPS_DIR}/pybind11/${_rigidfem_pybind11_rel}" CACHE PATH
        "pybind11's CMake package (a copy, see cmake/StableDependencies.cmake)" FORCE)
    find_package(pybind11 CONFIG REQUIRED PATHS "${pybind11_DIR}" NO_DEFAULT_PATH)
  else()
    # No pybind11 module in the build's Python: whatever CMake finds, copied by nobody.
    find_package(pybind11 CONFIG REQUIRED)
  endif()
endmacro()

function(rigidfem_find_eigen)
  # A system Eigen 3.4 first, otherwise the cmeel-eigen wheel of the build requirements
  # (<site>/cmeel.prefix, a prefix CMake does not search by itself). Either way the compile
  # commands name a copy of its headers.
  find_package(Eigen3 3.4 QUIET CONFIG)
  if(NOT Eigen3_FOUND)
    _rigidfem_python_answer(prefixes
      "import os, sys; print(';'.join(os.path.join(p, 'cmeel.prefix') for p in sys.path if os.path.isdir(os.path.join(p, 'cmeel.prefix'))))")
    find_package(Eigen3 3.4 REQUIRED CONFIG PATHS ${prefixes} NO_DEFAULT_PATH)
  endif()
  get_target_property(includes Eigen3::Eigen INTERFACE_INCLUDE_DIRECTORIES)
  list(LENGTH includes count)
  if(NOT count EQUAL 1 OR NOT EXISTS "${includes}/Eigen/Core")
    message(FATAL_ERROR "rigidfem: unexpected include directories of Eigen3::Eigen: ${includes}")
  endif()
  rigidfem_sync_tree("${includes}" "${RIGIDFEM_DEPS_DIR}/eigen3")
  add_library(rigidfem_eigen INTERFACE)
  target_include_directories(rigidfem_eigen SYSTEM INTERFACE "${RIGIDFEM_DEPS_DIR}/eigen3")
  get_target_property(definitions Eigen3::Eigen INTERFACE_COMPILE_DEFINITIONS)
  if(definitions)
    target_compile_definitions(rigidfem_eigen INTERFACE ${definitions})
  endif()
  message(STATUS "rigidfem: Eigen ${Eigen3_VERSION} from ${includes}, copied to ${RIGIDFEM_DEPS_DIR}/eigen3")
endfunction()
