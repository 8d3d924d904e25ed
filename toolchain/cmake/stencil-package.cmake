# What installs (cmake --install, GNUInstallDirs) and the Debian package built from it (make package:
# CPack's DEB generator). The package holds the programs, the display's page, the sample parts, the
# example configuration, man pages, the systemd units and the udev rule; it depends on runtime
# libraries only (dpkg-shlibdeps finds them from the programs) and adduser for its service user.
include(GNUInstallDirs)

set(stencil_programs stencil-sim stencil-rig stencil-display stencil-journal stencil-tablegen stencil-sample-parts)
set(stencil_installed_programs)
foreach(program IN LISTS stencil_programs)
  if(TARGET ${program})
    list(APPEND stencil_installed_programs ${program})
  endif()
endforeach()
install(TARGETS ${stencil_installed_programs} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

set(stencil_share ${CMAKE_INSTALL_DATADIR}/stencil)
if(TARGET stencil_hmi_page)
  install(DIRECTORY ${STENCIL_HMI_ASSETS}/ DESTINATION ${stencil_share}/page)
endif()
file(GLOB stencil_part_files ${PROJECT_SOURCE_DIR}/sim/parts/*.stl)
install(FILES ${stencil_part_files} DESTINATION ${stencil_share}/parts)
install(FILES ${PROJECT_SOURCE_DIR}/board/sherline_suzuki/rig.toml DESTINATION ${stencil_share}/examples)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/stencil)
# The units name the programs where this install puts them (@BINDIR@ at install time: /usr/bin in the
# package, <prefix>/bin for cmake --install --prefix). systemd and udev read only /usr/lib and /etc:
# the units and the rule take effect from the package (prefix /usr).
foreach(unit IN ITEMS stencil-rig.service stencil-display.service)
  install(CODE "
    set(BINDIR \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}\")
    configure_file(\"${PROJECT_SOURCE_DIR}/toolchain/package/${unit}\" \"${CMAKE_BINARY_DIR}/units/${unit}\" @ONLY)
    file(INSTALL DESTINATION \"\${CMAKE_INSTALL_PREFIX}/lib/systemd/system\" TYPE FILE
         FILES \"${CMAKE_BINARY_DIR}/units/${unit}\")")
endforeach()
install(FILES ${PROJECT_SOURCE_DIR}/toolchain/package/60-stencil-uio.rules DESTINATION lib/udev/rules.d)

# Man pages from each program's --help and --version (help2man, a build tool: toolchain/install-deps.sh).
find_program(HELP2MAN_PROGRAM help2man)
if(HELP2MAN_PROGRAM)
  set(stencil_man_pages)
  set(name_stencil-sim "the haptic stencil controller against a simulated device, CY545 and mill")
  set(name_stencil-rig "the haptic stencil controller on the rig, and its control commands")
  set(name_stencil-display "the haptic stencil controller's operator display (a web page)")
  set(name_stencil-journal "what a haptic stencil job's journal holds")
  set(name_stencil-tablegen "STL part and tool to the stencil's validated tables (.stbl)")
  set(name_stencil-sample-parts "write the haptic stencil's sample parts as STL")
  foreach(program IN LISTS stencil_installed_programs)
    set(page ${CMAKE_BINARY_DIR}/man/${program}.1)
    add_custom_command(OUTPUT ${page}.gz
      COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_BINARY_DIR}/man
      COMMAND ${HELP2MAN_PROGRAM} --no-info --no-discard-stderr --section=1 --source=stencil
              "--name=${name_${program}}" --output=${page} $<TARGET_FILE:${program}>
      COMMAND gzip -9nf ${page}
      DEPENDS ${program}
      COMMENT "help2man: ${program}.1"
      VERBATIM)
    list(APPEND stencil_man_pages ${page}.gz)
  endforeach()
  add_custom_target(stencil_man_pages ALL DEPENDS ${stencil_man_pages})
  install(FILES ${stencil_man_pages} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
else()
  message(STATUS "help2man not found: no man pages (toolchain/install-deps.sh installs it)")
endif()

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME stencil)
set(CPACK_PACKAGE_VENDOR "haptic stencil project")
set(CPACK_PACKAGE_CONTACT "haptic stencil maintainers <stencil@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "haptic stencil controller: a hand-guided mill that cannot cut into the part")
set(CPACK_PACKAGE_DESCRIPTION "The haptic stencil controller for a desktop mill guided by hand through a force-feedback
device: the real-time controller (stencil-rig) with its systemd service, the operator display
(stencil-display), the table generator (stencil-tablegen), the host simulation (stencil-sim) and
sample parts.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_STRIP_FILES ON)  # the programs without their symbols: a third of the size
set(CPACK_DEBIAN_PACKAGE_DEPENDS "adduser")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${PROJECT_SOURCE_DIR}/toolchain/package/postinst ${PROJECT_SOURCE_DIR}/toolchain/package/prerm
    ${PROJECT_SOURCE_DIR}/toolchain/package/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
# The version at packaging time, not at configure time: toolchain/cmake/stencil-package-version.cmake
# runs inside cpack and asks git (0.1.0+g<commit>[.dirty]).
set(STENCIL_SOURCE_DIR ${PROJECT_SOURCE_DIR})
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
configure_file(${PROJECT_SOURCE_DIR}/toolchain/cmake/stencil-package-version.cmake.in
               ${CMAKE_BINARY_DIR}/stencil-package-version.cmake @ONLY)
set(CPACK_PROJECT_CONFIG_FILE ${CMAKE_BINARY_DIR}/stencil-package-version.cmake)
include(CPack)

# ctest label `package` (make package-check; the default test presets leave it out): the package built,
# then installed, used and purged in a clean Debian 12 root. Needs root and Debian's archive.
if(STENCIL_BUILD_TESTS)
  add_test(NAME package.install_use_and_purge_in_a_clean_debian_12
           COMMAND bash -c "cmake --build '${CMAKE_BINARY_DIR}' --target package >/dev/null && bash '${PROJECT_SOURCE_DIR}/toolchain/package-check.sh' --remove-root '${CMAKE_BINARY_DIR}/package-check' '${CMAKE_BINARY_DIR}'")
  set_tests_properties(package.install_use_and_purge_in_a_clean_debian_12 PROPERTIES LABELS package TIMEOUT 1800)
endif()
