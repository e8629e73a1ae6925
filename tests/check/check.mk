# `make check`: the everyday tier (<= 60 s on 2 cores): the fast C unit and property tests, the
# CLI contract, the limit against OpenSubdiv, and the add-on's modifier cases on the newest
# Blender line. `make test` runs everything (tests/run_tests.sh).
CHECK_TESTS = test_mesh test_bspline_oracle test_patches test_fixed_bugs test_fvar test_limit \
              test_locality test_cad_writer test_ev_select test_badinput test_badinput_plan \
              test_export test_suzanne test_recreate test_eigen
.PHONY: check
check: deps
	@$(MAKE) --no-print-directory -j$(TEST_JOBS) build $(CHECK_TESTS:%=$(B)/tests/%) \
	  $(B)/ccnurbs.zip $(B)/osd_refine $(B)/objdiff
	@sh tests/check/check.sh $(CHECK_TESTS)
