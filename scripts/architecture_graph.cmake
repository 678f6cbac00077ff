# CMakeGraphVizOptions for scripts/architecture_graph.sh: rastray's own
# libraries and the rastray program only (tests, fuzzers, peers and the
# benchmark binary left out; external packages left out).
set(GRAPHVIZ_GRAPH_NAME "rastray")
set(GRAPHVIZ_EXTERNAL_LIBS FALSE)
set(GRAPHVIZ_GENERATE_PER_TARGET FALSE)
set(GRAPHVIZ_GENERATE_DEPENDERS FALSE)
set(GRAPHVIZ_EXECUTABLES TRUE)
set(GRAPHVIZ_OBJECT_LIBS FALSE)
set(GRAPHVIZ_IGNORE_TARGETS ".*_tests$" "rastray_test_support" "^gtest" "^gmock" ".*fuzzer.*" "render_bench"
    ".*_peer$" "^benchmark" "^stb$" "rastray_web_assets" "rastray_peer_common")
