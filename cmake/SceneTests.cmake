# One ctest per scene in scenes/, in two families, both run by plain `ctest`
# (so by ci/test.sh and .ci/run):
#   pov/NAME     label pov: `rayaudit compare`, our render against POV-Ray 3.7's,
#                judged by scenes/pov/NAME.json (default: identical at 8 bits);
#                a scene POV cannot express is a visible skip with its reason.
#   golden/NAME  label golden: `rayaudit golden check`, against golden/NAME.png;
#                on failure the diff image goes to BUILD/golden-diffs/.
# The whole mesh ladder in scenes/corpus/ (12, 992, 9,334, 69,666 and 871,414
# triangles; about 1 s each per test, the bunny's pov/ test about 2 s and the
# dragon's, 640 x 480, about 12 s) is checked too, named corpus/NAME; they
# skip when ci/fetch-corpus.sh has not filled the cache. So do two corpus scenes
# of the POV-Ray differential tests: cornell-box (a pixel POV-Ray's mesh2 inside test decides) and
# spider-textured (POV's mesh2 UVs, hit point and float32 data).
file(GLOB RAYAUDIT_SCENES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/scenes/*.json)
foreach(rung ladder-10-box ladder-1k-teapot-npm ladder-10k-cheese-ball ladder-100k-bunny ladder-1M-dragon
        cornell-box spider-textured)
  list(APPEND RAYAUDIT_SCENES ${PROJECT_SOURCE_DIR}/scenes/corpus/${rung}.json)
endforeach()
set(RAYAUDIT_POV_OUT ${CMAKE_BINARY_DIR}/pov-compare)
file(MAKE_DIRECTORY ${RAYAUDIT_POV_OUT} ${RAYAUDIT_POV_OUT}/corpus)
foreach(scene ${RAYAUDIT_SCENES})
  # The path under scenes/ without .json: sphere-on-plane, corpus/ladder-10-box.
  file(RELATIVE_PATH name ${PROJECT_SOURCE_DIR}/scenes ${scene})
  string(REGEX REPLACE "\\.json$" "" name "${name}")
  add_test(NAME pov/${name}
           COMMAND rayaudit compare ${scene} --skip-inexpressible
                   --diff ${RAYAUDIT_POV_OUT}/${name}.diff.png --json ${RAYAUDIT_POV_OUT}/${name}.json)
  set_tests_properties(pov/${name} PROPERTIES LABELS pov SKIP_RETURN_CODE 77 TIMEOUT 300)
  add_test(NAME golden/${name}
           COMMAND rayaudit golden check ${name} --skip-unavailable --root ${PROJECT_SOURCE_DIR}
                   --diff-dir ${CMAKE_BINARY_DIR}/golden-diffs)
  set_tests_properties(golden/${name} PROPERTIES LABELS golden SKIP_RETURN_CODE 77 TIMEOUT 300)
endforeach()

