#!/usr/bin/env python3
"""Self-test of long_functions.py on inline C++ snippets (ctest: long_functions_selftest)."""
import contextlib
import io
import os
import sys
import tempfile
import textwrap
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import long_functions as lf  # noqa: E402


def cc(text):
    return textwrap.dedent(text).lstrip("\n")


def statements(n, indent="  "):
    """n lines of a function body."""
    return "".join(f"{indent}x += {i};\n" for i in range(n))


def functions(text):
    """{name: (first line, last line)} of every function the scanner finds."""
    found = {}
    for name, first, last in lf.Scanner(text).scan():
        assert name not in found, f"{name} found twice"
        found[name] = (first, last)
    return found


class FindsFunctions(unittest.TestCase):
    def test_namespace_functions_run_from_their_name_to_their_closing_brace(self):
        text = cc("""
            #include <vector>

            namespace brdf::interp {
            namespace {

            int Small(int x) {
              return x + 1;
            }

            }  // namespace

            std::vector<int>
            Grid::Build(const Cloud& cloud,
                        int depth) const {
            """) + statements(5) + cc("""
            }

            template <int D>
            auto Twice(int x) noexcept(D > 2) -> int {
              return 2 * x;
            }
            }  // namespace brdf::interp
            """)
        self.assertEqual(functions(text), {
            "Small": (6, 8),
            "Grid::Build": (13, 20),
            "Twice": (23, 25),
        })

    def test_class_bodies_are_not_functions_but_their_inline_methods_are(self):
        text = cc("""
            class CAPABILITY("mutex") Mutex {
             public:
              Mutex() = default;
              explicit Mutex(int n) : n_(n), names_{"a", "b"}, opts_(Options{}) {
                Check();
              }
              ~Mutex() {
                n_ = 0;
              }
              void Lock() ACQUIRE() { mu_.lock(); }
              bool operator==(const Mutex& o) const { return n_ == o.n_; }
              explicit operator bool() const { return n_ != 0; }

             private:
              struct Options {
                int depth{3};
                int Depth() const & { return depth; }
              };
              enum class Mode { kA, kB };
              int n_ = 0;
              std::vector<std::string> names_{"x", "y"};
              std::function<void(int)> hook_ = [](int v) { Use(v); };
            };
            """)
        self.assertEqual(functions(text), {
            "Mutex::Mutex": (4, 6),
            "Mutex::~Mutex": (7, 9),
            "Mutex::Lock": (10, 10),
            "Mutex::operator==": (11, 11),
            "Mutex::operator bool": (12, 12),
            "Mutex::Options::Depth": (17, 17),
        })

    def test_lambdas_and_local_classes_belong_to_their_function(self):
        text = cc("""
            int Outer(std::vector<int>& v) {
              auto by_size = [&](int a, int b) {
                return a < b;
              };
              struct Local {
                int Get() const { return 1; }
              } local;
              std::sort(v.begin(), v.end(), [](int a, int b) { return a > b; });
              return local.Get();
            }
            const auto kAtNamespaceScope = [](int a) {
              return a * 2;
            };
            int After() { return 0; }
            """)
        self.assertEqual(functions(text), {"Outer": (1, 10), "After": (14, 14)})

    def test_braces_in_strings_comments_literals_and_macros_do_not_count(self):
        text = cc("""
            #define OPEN {
            #define BLOCK(x) \\
              do { x; } while (0)
            // A comment with a brace {
            /* and a block comment with one } and { */
            const char* Text() {
              const char* a = "a { in a string \\" }";
              char b = '{';
              char c = '\\'';
              const char* raw = R"json({"key": "}"})json";
              int big = 1'000'000;  // a digit separator, not a character literal
              return u8"}";
            }
            int Next() { return '}'; }
            """)
        self.assertEqual(functions(text), {"Text": (6, 13), "Next": (14, 14)})

    def test_initializers_are_not_functions(self):
        text = cc("""
            const std::map<int, int> kTable = {{1, 2}, {3, 4}};
            Options kDefaults{.depth = 3};
            const Grid kGrid = MakeGrid({1, 2, 3});
            int Later() { return kGrid.size(); }
            """)
        self.assertEqual(functions(text), {"Later": (4, 4)})

    def test_tests_are_named_with_their_suite_and_case(self):
        text = cc("""
            TEST_F(GridTest, FindsTheWinners) {
              EXPECT_EQ(1, 1);
            }
            """)
        self.assertEqual(functions(text), {"TEST_F(GridTest, FindsTheWinners)": (1, 3)})


class Reports(unittest.TestCase):
    def run_main(self, files, *args):
        with tempfile.TemporaryDirectory() as folder:
            for name, text in files.items():
                path = os.path.join(folder, name)
                os.makedirs(os.path.dirname(path), exist_ok=True)
                with open(path, "w") as f:
                    f.write(text)
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                code = lf.main([folder, *args])
            return code, out.getvalue().replace(folder + os.sep, "")

    FILES = {
        "a/long.cc": "int Long() {\n" + statements(9) + "}\n" + "int Short() {\n  return 0;\n}\n",
        "b/longer.h": "struct S {\n  void Longer() {\n" + statements(12, "    ") + "  }\n};\n",
        "b/ignored.py": "def f():\n" + "    pass\n" * 20,
    }

    def test_lists_the_long_ones_longest_first_with_the_count(self):
        code, out = self.run_main(self.FILES, "--max", "10")
        self.assertEqual(code, 0)
        self.assertEqual(out.splitlines(), [
            "b/longer.h:2 S::Longer 14 lines",
            "a/long.cc:1 Long 11 lines",
            "2 functions over 10 lines",
        ])

    def test_fail_exits_1_only_when_one_is_too_long(self):
        self.assertEqual(self.run_main(self.FILES, "--max", "10", "--fail")[0], 1)
        code, out = self.run_main(self.FILES, "--max", "14", "--fail")
        self.assertEqual((code, out), (0, "0 functions over 14 lines\n"))

    def test_default_limit_is_80(self):
        files = {"f.cc": "void F() {\n" + statements(79) + "}\n"}  # 81 lines
        self.assertEqual(self.run_main(files)[1].splitlines(), ["f.cc:1 F 81 lines",
                                                                "1 functions over 80 lines"])


if __name__ == "__main__":
    unittest.main()
