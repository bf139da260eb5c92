# The fuzz preset (SAARCOR_FUZZ=ON, clang): the libFuzzer harnesses (foo_fuzz.cpp beside the code
# they fuzz) and only the libraries they need, every object instrumented with
# -fsanitize=${SAARCOR_FUZZ_SANITIZERS} (the libraries with fuzzer-no-link: coverage without a
# main). rtl/, the benchmarks, the unit tests and the saarcor program are not built here.
# CTest: fuzz.<harness> runs each harness 30 s on its seeds (label fuzz, `ctest --preset fuzz`),
# fuzz_deep.<harness> 1M executions (label deep, `ctest --preset fuzz-deep`). docs/fuzzing.md.

if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  message(FATAL_ERROR "SAARCOR_FUZZ needs clang (libFuzzer): configure with the fuzz preset")
endif()

set(SAARCOR_FUZZ_SANITIZERS "fuzzer,address,undefined" CACHE STRING
    "-fsanitize= list of the harnesses (the libraries get fuzzer-no-link instead of fuzzer)")
string(REPLACE "fuzzer" "fuzzer-no-link" _saarcor_lib_sanitizers "${SAARCOR_FUZZ_SANITIZERS}")
add_compile_options(-fsanitize=${_saarcor_lib_sanitizers} -fno-omit-frame-pointer
                    -fno-sanitize-recover=undefined)
# The datapaths combine flags with '&' on purpose (branch-free, as the hardware does); clang's
# -Wbitwise-instead-of-logical (GCC has no such warning) would stop them under -Werror.
target_compile_options(saarcor_warnings INTERFACE -Wno-bitwise-instead-of-logical)

# Libraries: the folders the harnesses link, built as in every preset (library only).
add_subdirectory(fixedfloat)
add_subdirectory(hw)
add_subdirectory(memif)
add_subdirectory(host)
# Of units/ and testbench/ only the files the harnesses call (their folder libraries need the
# whole cycle model and every tool): the parameter tables and the vector file's reader with the
# datapath it checks against, and the names of added units that unit_name and phase_name look up.
add_library(saarcor_fuzz_units STATIC
  ${PROJECT_SOURCE_DIR}/units/cycle_params.cpp
  ${PROJECT_SOURCE_DIR}/units/unit_vectors.cpp
  ${PROJECT_SOURCE_DIR}/units/functional_model.cpp
  ${PROJECT_SOURCE_DIR}/units/request_trace.cpp
  ${PROJECT_SOURCE_DIR}/units/unit_registry.cpp)
target_include_directories(saarcor_fuzz_units PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(saarcor_fuzz_units PUBLIC saarcor::memif saarcor::fixedfloat
  PRIVATE saarcor_warnings)
add_library(saarcor_fuzz_testbench STATIC ${PROJECT_SOURCE_DIR}/testbench/vector_file.cpp)
target_link_libraries(saarcor_fuzz_testbench PUBLIC saarcor_fuzz_units PRIVATE saarcor_warnings)

set(SAARCOR_SHARED_SCENES_DIR "${PROJECT_SOURCE_DIR}/../shared/scenes")

# saarcor_fuzz_harness(NAME <target> SOURCE <file> DEPS <libs...> [SEEDS <dirs...>]
#                      [SEED_FILES <files...>] [DICT <file>])
# SEED_FILES are linked (symbolic links, never copies) into <build>/fuzz/<target>/seeds at
# configure time; SEEDS are seed folders used as they are. New inputs libFuzzer finds go to
# <build>/fuzz/<target>/corpus, crashes to <build>/fuzz/<target>/crash-*.
function(saarcor_fuzz_harness)
  cmake_parse_arguments(H "" "NAME;SOURCE;DICT" "DEPS;SEEDS;SEED_FILES" ${ARGN})
  add_executable(${H_NAME} ${H_SOURCE})
  target_link_libraries(${H_NAME} PRIVATE ${H_DEPS} saarcor_warnings)
  target_compile_options(${H_NAME} PRIVATE -fsanitize=${SAARCOR_FUZZ_SANITIZERS})
  target_link_options(${H_NAME} PRIVATE -fsanitize=${SAARCOR_FUZZ_SANITIZERS})
  target_compile_definitions(${H_NAME} PRIVATE
    SAARCOR_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    SAARCOR_SHARED_SCENES="${SAARCOR_SHARED_SCENES_DIR}")
  set(_dir ${CMAKE_BINARY_DIR}/fuzz/${H_NAME})
  file(MAKE_DIRECTORY ${_dir}/corpus)
  set(_seed_dirs ${H_SEEDS})
  if(H_SEED_FILES)
    file(REMOVE_RECURSE ${_dir}/seeds)
    file(MAKE_DIRECTORY ${_dir}/seeds)
    foreach(_f ${H_SEED_FILES})
      # Folder and file name: Box/Box.gltf -> Box_Box.gltf (the names repeat across folders).
      get_filename_component(_parent ${_f} DIRECTORY)
      get_filename_component(_parent ${_parent} NAME)
      get_filename_component(_name ${_f} NAME)
      file(CREATE_LINK ${_f} ${_dir}/seeds/${_parent}_${_name} SYMBOLIC)
    endforeach()
    list(APPEND _seed_dirs ${_dir}/seeds)
  endif()
  set(_args -rss_limit_mb=2048 -timeout=25 -print_final_stats=1 -artifact_prefix=${_dir}/)
  if(H_DICT)
    list(APPEND _args -dict=${H_DICT})
  endif()
  string(REGEX REPLACE "_fuzz$" "" _short ${H_NAME})
  add_test(NAME fuzz.${_short}
    COMMAND ${H_NAME} -max_total_time=30 ${_args} ${_dir}/corpus ${_seed_dirs})
  # OpenImageIO (not instrumented) keeps the error text of an image it failed to decode.
  set(_env "LSAN_OPTIONS=suppressions=${PROJECT_SOURCE_DIR}/host/fuzz/lsan.supp")
  set_tests_properties(fuzz.${_short} PROPERTIES LABELS fuzz TIMEOUT 600 ENVIRONMENT "${_env}")
  add_test(NAME fuzz_deep.${_short}
    COMMAND ${H_NAME} -runs=1000000 ${_args} ${_dir}/corpus ${_seed_dirs})
  set_tests_properties(fuzz_deep.${_short} PROPERTIES
    LABELS deep TIMEOUT 36000 ENVIRONMENT "${_env}")
endfunction()

# glTF: every .gltf/.glb of the shared scenes and the project's room.glb. The harness finds the
# files a .gltf refers to (buffers, images) beside its input (host/gltf_loader_fuzz.cpp).
file(GLOB _gltf_seeds ${SAARCOR_SHARED_SCENES_DIR}/*/*.gltf ${SAARCOR_SHARED_SCENES_DIR}/*/*.glb)
saarcor_fuzz_harness(NAME gltf_loader_fuzz SOURCE ${PROJECT_SOURCE_DIR}/host/gltf_loader_fuzz.cpp
  DEPS saarcor::host
  SEED_FILES ${_gltf_seeds} ${PROJECT_SOURCE_DIR}/scenes/room.glb
  DICT ${PROJECT_SOURCE_DIR}/host/fuzz/gltf.dict)

# AFF: the BART files up to 64 KiB (the mesh files above it make an execution slow; includes of
# them fail as "not found" in the harness's folder).
file(GLOB _aff_all ${SAARCOR_SHARED_SCENES_DIR}/BART/*/aff/*.aff)
set(_aff_seeds "")
foreach(_f ${_aff_all})
  file(SIZE ${_f} _size)
  if(_size LESS_EQUAL 65536)
    list(APPEND _aff_seeds ${_f})
  endif()
endforeach()
saarcor_fuzz_harness(NAME aff_loader_fuzz SOURCE ${PROJECT_SOURCE_DIR}/host/aff_loader_fuzz.cpp
  DEPS saarcor::host
  SEED_FILES ${_aff_seeds}
  DICT ${PROJECT_SOURCE_DIR}/host/fuzz/aff.dict)

# --preset / --set KEY=VALUE (cycle keys and kd.* keys).
saarcor_fuzz_harness(NAME config_fuzz SOURCE ${PROJECT_SOURCE_DIR}/testbench/config_fuzz.cpp
  DEPS saarcor_fuzz_units saarcor::host
  SEEDS ${PROJECT_SOURCE_DIR}/testbench/fuzz/config
  DICT ${PROJECT_SOURCE_DIR}/testbench/fuzz/config.dict)

# `saarcor vectors --check FILE`.
saarcor_fuzz_harness(NAME vector_file_fuzz
  SOURCE ${PROJECT_SOURCE_DIR}/testbench/vector_file_fuzz.cpp
  DEPS saarcor_fuzz_testbench
  SEEDS ${PROJECT_SOURCE_DIR}/testbench/fuzz/vectors
  DICT ${PROJECT_SOURCE_DIR}/testbench/fuzz/vectors.dict)
