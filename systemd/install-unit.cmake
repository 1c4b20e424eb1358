# Run by `cmake --install` (install(SCRIPT) in the top-level CMakeLists.txt):
# writes the unit with ExecStart naming the binary where this install puts
# it, so that `--prefix /usr/local` (or any other) yields a unit that starts.
file(READ "${PVTWIN_UNIT_SOURCE}" unit)
string(REPLACE "/usr/bin/pvtwin" "${CMAKE_INSTALL_PREFIX}/${PVTWIN_BINDIR}/pvtwin" unit "${unit}")
set(target "$ENV{DESTDIR}${CMAKE_INSTALL_PREFIX}/lib/systemd/system/pvtwin.service")
message(STATUS "Installing: ${target}")
file(WRITE "${target}" "${unit}")
