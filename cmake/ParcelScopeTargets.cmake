# One function creates every library target of the project, so that warnings,
# include layout and sanitizer flags are the same everywhere.
#
# parcelscope_add_library(NAME
#   SOURCES src/a.cpp ...
#   PUBLIC_DEPS  parcelscope_core ...      (project targets whose headers we expose)
#   PRIVATE_DEPS GDAL::GDAL ...            (third-party libraries, never exposed))
function(parcelscope_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
    -Wno-sign-conversion)
  if(PARCELSCOPE_WARNINGS_AS_ERRORS)
    # GCC 12 reports maybe-uninitialized inside CGAL's inlined filtered predicates.
    target_compile_options(${target} PRIVATE -Werror -Wno-error=maybe-uninitialized)
  endif()
  if(PARCELSCOPE_SANITIZE)
    # vptr checks are off: CGAL's arrangement iterators downcast DCEL records by
    # design, which UBSan reports (and whose reports leak in the demangler).
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-sanitize=vptr -fno-sanitize-recover=all
      -fno-omit-frame-pointer)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
endfunction()

function(parcelscope_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC "${CMAKE_CURRENT_SOURCE_DIR}/include"
                                     PRIVATE "${CMAKE_CURRENT_SOURCE_DIR}/src")
  target_link_libraries(${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  parcelscope_set_warnings(${name})
  if(PARCELSCOPE_SANITIZE)
    target_link_options(${name} INTERFACE -fsanitize=address,undefined)
  endif()
endfunction()

# The executables' allocator: tcmalloc where found (PARCELSCOPE_TCMALLOC).
function(parcelscope_use_allocator target)
  if(TARGET PkgConfig::TCMALLOC)
    target_link_libraries(${target} PRIVATE PkgConfig::TCMALLOC)
  endif()
endfunction()
