# make bench (not part of make test): benchmark drivers and the comparison script.
BENCH_SAVED_GOAL := $(.DEFAULT_GOAL)
$(B)/bench/ccn_bench: tests/bench/bench.c $(B)/libccnurbs.a
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(WARN) -O2 $< -o $@ $(B)/libccnurbs.a $(LDLIBS)
$(B)/bench/export_bench: tests/bench/export_bench.c $(B)/libccnurbs.a
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS) $(WARN) -O2 $< -o $@ $(B)/libccnurbs.a $(LDLIBS)
$(B)/bench/osd_bench: tests/bench/osd_bench.cpp
	@mkdir -p $(@D)
	$(CXX) -std=c++14 -O2 -Wall -Wextra -Werror $< -o $@ -losdCPU
.PHONY: bench
bench: deps
	@$(MAKE) --no-print-directory build package $(B)/bench/ccn_bench $(B)/bench/export_bench $(B)/bench/osd_bench
	@./tests/bench/bench.sh
.DEFAULT_GOAL := $(BENCH_SAVED_GOAL)
