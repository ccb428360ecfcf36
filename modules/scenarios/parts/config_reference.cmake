# The config reference (docs/config_reference.md): each scenario's key table lives next to its
# reader (<name>/config_keys.cpp, listed in that scenario's part); this test checks every table
# against the keys its reader reads.
list(APPEND scenarios_tests test/config_keys_test.cpp)
