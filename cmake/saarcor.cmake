# Shared build settings: warnings, sanitizers, strict floating point, and the helper that turns a
# folder into a library + test program + benchmark program by file name convention
# (foo.cpp -> library, foo_test.cpp -> <folder>_tests, foo_bench.cpp -> <folder>_bench).

add_library(saarcor_warnings INTERFACE)
target_compile_options(saarcor_warnings INTERFACE -Wall -Wextra -Wpedantic
  $<$<BOOL:${SAARCOR_WERROR}>:-Werror>
  # GCC 12 reports false -Wrestrict/-Wstringop-overflow inside libstdc++ string code at -O2/-O3
  # (GCC bug 105329); they say nothing about our code. (Clang, the fuzz preset's compiler, has
  # neither warning.)
  $<$<CXX_COMPILER_ID:GNU>:-Wno-restrict -Wno-stringop-overflow>
  # Bit-exact arithmetic and the float reference must never be contracted into FMA.
  -ffp-contract=off)
target_compile_definitions(saarcor_warnings INTERFACE $<$<BOOL:${SAARCOR_SANITIZE}>:SAARCOR_SANITIZED=1>)
if(SAARCOR_SANITIZE)
  target_compile_options(saarcor_warnings INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
    -fno-sanitize-recover=undefined)
  target_link_options(saarcor_warnings INTERFACE -fsanitize=address,undefined)
endif()

# saarcor_folder(NAME <lib> DEPS <public deps...> [TEST_DEPS ...] [BENCH_DEPS ...] [EXCLUDE <files...>])
# foo_fuzz.cpp (a libFuzzer harness) is never part of the library; cmake/fuzz.cmake builds the
# harnesses in the fuzz preset (SAARCOR_FUZZ), where saarcor_folder builds the library only.
function(saarcor_folder)
  cmake_parse_arguments(F "" "NAME" "DEPS;TEST_DEPS;BENCH_DEPS;EXCLUDE" ${ARGN})
  file(GLOB _all CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  file(GLOB _tests CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*_test.cpp)
  file(GLOB _benches CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*_bench.cpp)
  file(GLOB _fuzz CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*_fuzz.cpp)
  # foo_deep_test.cpp: full-size runs, in <folder>_deep_tests with the ctest label "deep", left
  # out of the default test presets (ctest --preset deep runs them).
  file(GLOB _deep CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*_deep_test.cpp)
  if(_deep)
    list(REMOVE_ITEM _tests ${_deep})
  endif()
  set(_lib ${_all})
  if(_tests)
    list(REMOVE_ITEM _lib ${_tests})
  endif()
  if(_benches)
    list(REMOVE_ITEM _lib ${_benches})
  endif()
  foreach(_ex ${F_EXCLUDE})
    list(REMOVE_ITEM _lib ${CMAKE_CURRENT_SOURCE_DIR}/${_ex})
  endforeach()
  if(_deep)
    list(REMOVE_ITEM _lib ${_deep})
  endif()
  if(_fuzz)
    list(REMOVE_ITEM _lib ${_fuzz})
  endif()
  if(SAARCOR_FUZZ)
    set(_tests "")
    set(_deep "")
    set(_benches "")
  endif()
  if(_lib)
    add_library(saarcor_${F_NAME} STATIC ${_lib})
    target_include_directories(saarcor_${F_NAME} PUBLIC ${PROJECT_SOURCE_DIR})
    target_link_libraries(saarcor_${F_NAME} PUBLIC ${F_DEPS} PRIVATE saarcor_warnings)
  else()
    add_library(saarcor_${F_NAME} INTERFACE)
    target_include_directories(saarcor_${F_NAME} INTERFACE ${PROJECT_SOURCE_DIR})
    target_link_libraries(saarcor_${F_NAME} INTERFACE ${F_DEPS})
  endif()
  add_library(saarcor::${F_NAME} ALIAS saarcor_${F_NAME})
  if(_tests)
    add_executable(${F_NAME}_tests ${_tests})
    target_link_libraries(${F_NAME}_tests PRIVATE saarcor::${F_NAME} ${F_TEST_DEPS} GTest::gtest_main
      GTest::gmock saarcor_warnings)
    target_compile_definitions(${F_NAME}_tests PRIVATE
      SAARCOR_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
      SAARCOR_SHARED_SCENES="${PROJECT_SOURCE_DIR}/../shared/scenes"
      SAARCOR_BIN_DIR="${CMAKE_RUNTIME_OUTPUT_DIRECTORY}")
    gtest_discover_tests(${F_NAME}_tests DISCOVERY_TIMEOUT 60
      PROPERTIES LABELS ${F_NAME})
  endif()
  if(_deep)
    add_executable(${F_NAME}_deep_tests ${_deep})
    target_link_libraries(${F_NAME}_deep_tests PRIVATE saarcor::${F_NAME} ${F_TEST_DEPS}
      GTest::gtest_main GTest::gmock saarcor_warnings)
    target_compile_definitions(${F_NAME}_deep_tests PRIVATE
      SAARCOR_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
      SAARCOR_SHARED_SCENES="${PROJECT_SOURCE_DIR}/../shared/scenes"
      SAARCOR_BIN_DIR="${CMAKE_RUNTIME_OUTPUT_DIRECTORY}")
    gtest_discover_tests(${F_NAME}_deep_tests DISCOVERY_TIMEOUT 60
      PROPERTIES LABELS "deep;${F_NAME}")
  endif()
  if(_benches AND SAARCOR_BENCHMARKS)
    add_executable(${F_NAME}_bench ${_benches})
    target_link_libraries(${F_NAME}_bench PRIVATE saarcor::${F_NAME} ${F_BENCH_DEPS} benchmark::benchmark
      saarcor_warnings)
    target_compile_definitions(${F_NAME}_bench PRIVATE
      SAARCOR_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
      SAARCOR_SHARED_SCENES="${PROJECT_SOURCE_DIR}/../shared/scenes")
  endif()
endfunction()
