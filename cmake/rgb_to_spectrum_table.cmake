# The RGB-to-spectrum table (src/candela/spectral/rgb_to_spectrum_table.h) is fitted at build time by a
# small program of its own, as pbrt-v4 does, instead of at the start of every spectral render. Sets
# `out_var` to the generated source file, which the renderer library compiles.
function(candela_rgb_to_spectrum_table root out_var)
  add_executable(candela_make_rgb_to_spectrum_table ${root}/apps/make_rgb_to_spectrum_table/main.cpp
    ${root}/src/candela/spectral/rgb_to_spectrum_table.cpp ${root}/src/candela/spectral/cie.cpp)
  target_include_directories(candela_make_rgb_to_spectrum_table PRIVATE ${root}/src)
  target_link_libraries(candela_make_rgb_to_spectrum_table PRIVATE TBB::tbb)
  set(out ${CMAKE_CURRENT_BINARY_DIR}/generated/rgb_to_spectrum_table_data.cpp)
  add_custom_command(OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_CURRENT_BINARY_DIR}/generated
    COMMAND candela_make_rgb_to_spectrum_table ${out}
    DEPENDS candela_make_rgb_to_spectrum_table
    COMMENT "Fitting the RGB-to-spectrum table")
  set(${out_var} ${out} PARENT_SCOPE)
endfunction()
