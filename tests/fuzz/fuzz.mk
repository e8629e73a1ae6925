# libFuzzer harnesses (included by the main Makefile before its targets; B = build dir).
# The library is rebuilt with coverage + ASan + UBSan into $(B)/fuzz/obj/ and each
# tests/fuzz/fuzz_NAME.c is linked with -fsanitize=fuzzer into $(B)/fuzz/fuzz_NAME.
# `make fuzz FUZZ_SECONDS=N` runs each harness N seconds (default 60) through
# tests/fuzz/run_fuzz.sh; `make test` runs that script too (TEST_DEPS builds the binaries).
# fuzz_plan is built only once the library defines ccn_plan_evaluate (checked with nm at
# build time; until then its rule prints a note and run_fuzz.sh reports it as skipped).
FUZZ_SAVED_GOAL := $(.DEFAULT_GOAL)
FUZZ_SECONDS ?= 60
FUZZ_CC      = clang-14
FUZZ_SAN     = -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
FUZZ_CFLAGS  = -O1 -g $(FUZZ_SAN) $(filter-out -Werror,$(WARN))
FUZZ_HDRS    = $(wildcard csrc/*/*.h tests/fuzz/*.h)
FUZZ_OBJ     = $(LIB_SRC:csrc/%.c=$(B)/fuzz/obj/%.o)
FUZZ_BINS    = $(B)/fuzz/fuzz_obj $(B)/fuzz/fuzz_mesh $(B)/fuzz/fuzz_plan

.PHONY: fuzz fuzz-build
fuzz-build: $(FUZZ_BINS)
fuzz: deps
	@$(MAKE) --no-print-directory fuzz-build
	@FUZZ_SECONDS=$(FUZZ_SECONDS) sh tests/fuzz/run_fuzz.sh

$(B)/fuzz/obj/%.o: csrc/%.c $(FUZZ_HDRS)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(CPPFLAGS) $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link -c $< -o $@
$(B)/fuzz/libccnurbs_fuzz.a: $(FUZZ_OBJ)
	rm -f $@
	ar rcs $@ $^
$(B)/fuzz/fuzz_obj $(B)/fuzz/fuzz_mesh: $(B)/fuzz/%: tests/fuzz/%.c $(B)/fuzz/libccnurbs_fuzz.a \
                                       $(FUZZ_HDRS)
	$(FUZZ_CC) $(CPPFLAGS) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< -o $@ \
	    $(B)/fuzz/libccnurbs_fuzz.a $(LDLIBS)
# Not a file rule while the plan API is missing: the recipe decides at build time.
$(B)/fuzz/fuzz_plan: tests/fuzz/fuzz_plan.c $(B)/fuzz/libccnurbs_fuzz.a $(FUZZ_HDRS)
	@if nm $(B)/fuzz/libccnurbs_fuzz.a 2>/dev/null | grep -q ' T ccn_plan_evaluate$$'; then \
	  echo "$(FUZZ_CC) ... $< -o $@"; \
	  $(FUZZ_CC) $(CPPFLAGS) $(FUZZ_CFLAGS) -fsanitize=fuzzer $< -o $@ \
	      $(B)/fuzz/libccnurbs_fuzz.a $(LDLIBS); \
	else rm -f $@; echo "fuzz_plan: ccn_plan_evaluate not in the library yet, not built"; fi

TEST_DEPS += $(FUZZ_BINS)
.DEFAULT_GOAL := $(FUZZ_SAVED_GOAL)
