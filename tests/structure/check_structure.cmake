# The architecture of the whole tree, checked on every ctest run:
#  1. each folder of core/, io/ and daemon/ (and config/) opens with a
#     README.md that says what it holds and what it may depend on;
#  2. the dependency direction is one-way: a file in a folder includes only
#     the folders listed for it below (and its own);
#  3. no product file outside core/effects/ spells an effect of the
#     vocabulary (the one list, core/common/effect_list.h) as a string literal: generic code asks
#     the effect's module (core/effects/effect_module.h), it never tests a
#     name.
# A folder is "core/<x>", "io/<x>", "daemon/<x>", "daemon" (main.cc alone),
# "config" or "tests/support"; an include "a/b/c.h" names the folder "a/b"
# for core, io and daemon, "a" for config.
# Run: cmake -DSOURCE_DIR=<repo> -P tests/structure/check_structure.cmake
if(NOT SOURCE_DIR)
  message(FATAL_ERROR "pass -DSOURCE_DIR=<repository root>")
endif()

set(core_folders common data physics effects model fit forecast synth diagnosis monitor)
set(io_folders platform files modbus sim store weather fleet report)
set(daemon_folders service commands bench)

# May depend on (besides itself). core/ first, in its stage order.
set(allowed_core/common "")
set(allowed_core/data core/common)
set(allowed_core/physics core/common)
set(allowed_core/effects core/common core/physics)
set(allowed_core/model core/common core/physics core/effects)
set(allowed_core/fit core/common core/data core/physics core/effects core/model)
set(allowed_core/forecast core/common core/data core/physics core/effects core/model core/fit)
set(allowed_core/synth core/common core/data core/physics core/effects core/model)
set(allowed_core/diagnosis core/common core/data core/physics core/effects core/model core/fit
  core/forecast core/synth core/monitor)
set(allowed_core/monitor core/common core/data core/physics core/effects core/model core/fit
  core/synth)
set(all_core)
foreach(f IN LISTS core_folders)
  list(APPEND all_core core/${f})
endforeach()
set(allowed_config ${all_core})
set(base ${all_core} config)
set(allowed_io/platform ${base})
set(allowed_io/files ${base} io/platform)
set(allowed_io/modbus ${base} io/platform)
set(allowed_io/sim ${base} io/platform io/files io/modbus)
set(allowed_io/store ${base} io/platform)
set(allowed_io/weather ${base} io/platform io/files)
set(allowed_io/fleet ${base} io/platform)
set(allowed_io/report ${base} io/platform io/files)
set(all_io)
foreach(f IN LISTS io_folders)
  list(APPEND all_io io/${f})
endforeach()
set(allowed_daemon/service ${base} ${all_io})
# daemon/demo_config: the header generated from commands/demo_config.h.in.
set(allowed_daemon/commands ${base} ${all_io} daemon/service daemon/demo_config)
set(allowed_daemon/bench ${base} ${all_io} daemon/service daemon/commands daemon/demo_config
  tests/support)
set(allowed_daemon daemon/commands)

# The vocabulary: the names of the one list of effects, its X(name, Name)
# lines (core/common/effect_list.h).
# (A line's continuation backslash would escape the list separator: gone first.)
file(READ ${SOURCE_DIR}/core/common/effect_list.h effect_text)
string(REPLACE ";" "," effect_text "${effect_text}")
string(REPLACE "\\" "" effect_text "${effect_text}")
string(REPLACE "\n" ";" effect_lines "${effect_text}")
set(vocabulary "")
foreach(line IN LISTS effect_lines)
  if(line MATCHES "^  X\\(([a-z_]+), [A-Za-z]+\\)")
    list(APPEND vocabulary ${CMAKE_MATCH_1})
  endif()
endforeach()
list(LENGTH vocabulary vocabulary_size)
if(vocabulary_size LESS 2)
  message(FATAL_ERROR "structure: read ${vocabulary_size} effect names from core/common/effect_list.h; its X(name, Name) lines changed form")
endif()
# Literal effect names that are not the effect: a contract spelled the same
# way (file, name, why).
set(exempt
  "core/common/param_list.inc|irradiance_bias"  # the params.json key of the pyranometer scale error k
)

set(problems "")
set(checked "")
# Folders on disk the check does not know.
foreach(top core io daemon)
  file(GLOB present LIST_DIRECTORIES true RELATIVE ${SOURCE_DIR}/${top} ${SOURCE_DIR}/${top}/*)
  foreach(entry IN LISTS present)
    if(IS_DIRECTORY ${SOURCE_DIR}/${top}/${entry})
      list(FIND ${top}_folders ${entry} known)
      if(known EQUAL -1)
        string(APPEND problems "${top}/${entry}/: a folder the layering check does not know; add it to tests/structure/check_structure.cmake\n")
      endif()
    endif()
  endforeach()
endforeach()

# check_folder(<folder> <recurse>): README, includes and effect names of the
# files of <folder> (and below it with recurse).
function(check_folder folder recurse)
  set(readme ${SOURCE_DIR}/${folder}/README.md)
  if(NOT EXISTS ${readme})
    string(APPEND problems "${folder}/README.md is missing\n")
  else()
    file(READ ${readme} text)
    if(NOT text MATCHES "May depend on")
      string(APPEND problems "${folder}/README.md does not say what it may depend on ('May depend on')\n")
    endif()
  endif()
  if(recurse)
    file(GLOB_RECURSE sources ${SOURCE_DIR}/${folder}/*.h ${SOURCE_DIR}/${folder}/*.cc
      ${SOURCE_DIR}/${folder}/*.inc)
  else()
    file(GLOB sources ${SOURCE_DIR}/${folder}/*.h ${SOURCE_DIR}/${folder}/*.cc
      ${SOURCE_DIR}/${folder}/*.inc)
  endif()
  foreach(source IN LISTS sources)
    file(RELATIVE_PATH rel ${SOURCE_DIR} ${source})
    # One list item per line: ';' and brackets would split or join items.
    file(READ ${source} content)
    string(REPLACE ";" "," content "${content}")
    string(REPLACE "[" "(" content "${content}")
    string(REPLACE "]" ")" content "${content}")
    string(REPLACE "\\" "/" content "${content}")
    string(REPLACE "\n" ";" lines "${content}")
    foreach(line IN LISTS lines)
      set(dep "")
      if(line MATCHES "^#include \"(core|io|daemon|tests)/([a-z_]+)[/.]")
        set(dep ${CMAKE_MATCH_1}/${CMAKE_MATCH_2})
      elseif(line MATCHES "^#include \"config/")
        set(dep config)
      endif()
      if(dep)
        list(FIND allowed_${folder} ${dep} ok)
        if(NOT dep STREQUAL folder AND ok EQUAL -1)
          string(APPEND problems "${rel}: includes ${dep}/, but ${folder}/ may depend on: ${allowed_${folder}}\n")
        endif()
      endif()
      if(NOT folder STREQUAL "core/effects")
        # Code only: drop a // comment (good enough for this code base).
        string(REGEX REPLACE "//.*$" "" code "${line}")
        foreach(name IN LISTS vocabulary)
          string(FIND "${code}" "\"${name}\"" at)
          list(FIND exempt "${rel}|${name}" exempt_at)
          if(NOT at EQUAL -1 AND exempt_at EQUAL -1)
            string(APPEND problems "${rel}: names the effect \"${name}\"; ask its module (core/effects/) instead\n")
          endif()
        endforeach()
      endif()
    endforeach()
  endforeach()
  set(problems "${problems}" PARENT_SCOPE)
endfunction()

foreach(top core io daemon)
  foreach(f IN LISTS ${top}_folders)
    check_folder(${top}/${f} ON)
  endforeach()
endforeach()
check_folder(config OFF)

# main.cc, the only file of daemon/ itself.
file(GLOB daemon_top ${SOURCE_DIR}/daemon/*.cc ${SOURCE_DIR}/daemon/*.h)
foreach(source IN LISTS daemon_top)
  file(STRINGS ${source} includes REGEX "^#include \"")
  foreach(line IN LISTS includes)
    if(line MATCHES "^#include \"([a-z_]+/[a-z_]+)" AND NOT CMAKE_MATCH_1 STREQUAL "daemon/commands")
      file(RELATIVE_PATH rel ${SOURCE_DIR} ${source})
      string(APPEND problems "${rel}: includes ${CMAKE_MATCH_1}/, but daemon/ itself may depend on daemon/commands only\n")
    endif()
  endforeach()
endforeach()

if(problems)
  message(FATAL_ERROR "structure:\n${problems}")
endif()
message(STATUS "structure of core/, io/, daemon/, config/: layering, READMEs and effect names ok")
