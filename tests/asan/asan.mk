# Sanitized build (included by the main Makefile before its targets; B = build dir).
# The library, every tests/c/test_*.c and the CLI, built with clang-14 and
# -fsanitize=address,undefined -fno-sanitize-recover=all, into $(B)/asan/. `make test`
# builds them (TEST_DEPS) and tests/asan/run_asan.sh runs them; any sanitizer report fails.
# -Werror is left out here: a clang-only warning must not stop the sanitized run (the gcc
# build keeps -Werror). .DEFAULT_GOAL is saved/restored so this fragment does not become
# the default goal.
ASAN_SAVED_GOAL := $(.DEFAULT_GOAL)
ASAN_CC     = clang-14
ASAN_FLAGS  = -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer \
              -O1 -g
ASAN_WARN   = $(filter-out -Werror,$(WARN))
ASAN_HDRS   = $(wildcard csrc/*/*.h tests/c/*.h)
ASAN_OBJ    = $(LIB_SRC:csrc/%.c=$(B)/asan/obj/%.o)
ASAN_TESTS  = $(TEST_SRC:tests/c/%.c=$(B)/asan/tests/%)

.PHONY: asan
asan: $(B)/asan/libccnurbs.a $(B)/asan/ccnurbs $(ASAN_TESTS)

$(B)/asan/obj/%.o: csrc/%.c $(ASAN_HDRS)
	@mkdir -p $(@D)
	$(ASAN_CC) $(CPPFLAGS) $(ASAN_WARN) $(ASAN_FLAGS) -c $< -o $@
$(B)/asan/libccnurbs.a: $(ASAN_OBJ)
	@mkdir -p $(@D)
	rm -f $@
	ar rcs $@ $^
$(B)/asan/ccnurbs: $(wildcard csrc/tools/*.c) $(B)/asan/libccnurbs.a $(ASAN_HDRS)
	$(ASAN_CC) $(CPPFLAGS) $(ASAN_WARN) $(ASAN_FLAGS) $(wildcard csrc/tools/*.c) -o $@ \
	    $(B)/asan/libccnurbs.a $(LDLIBS)
$(B)/asan/tests/%: tests/c/%.c $(B)/asan/libccnurbs.a $(ASAN_HDRS)
	@mkdir -p $(@D)
	$(ASAN_CC) $(CPPFLAGS) -Itests/c $(ASAN_WARN) $(ASAN_FLAGS) $< -o $@ \
	    $(B)/asan/libccnurbs.a $(LDLIBS)

TEST_DEPS += $(B)/asan/ccnurbs $(ASAN_TESTS)
.DEFAULT_GOAL := $(ASAN_SAVED_GOAL)
