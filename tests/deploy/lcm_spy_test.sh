#!/bin/sh
# hoist-lcm-spy: --help, --version, bad usage (exit 2), its class path built
# from installed locations (and every class lcm-spy needs loads from it), and,
# under Xvfb, HOIST_CAGE's field view opened and painted without an
# exception (SpyFieldViewTest.java).  Exit 77 (skipped) without Java, the jars
# or Xvfb.
#   lcm_spy_test.sh HOIST_LCM_SPY TEST_SOURCE_DIR WORK_DIR
set -u
spy=$1 src=$2 work=$3
[ -x "$spy" ] || { echo "SKIP: $spy not built (no javac or lcm.jar at configure time)"; exit 77; }
command -v java >/dev/null 2>&1 && command -v javac >/dev/null 2>&1 || { echo "SKIP: no java/javac"; exit 77; }
fail() { echo "FAIL: $*"; exit 1; }
"$spy" --help | grep -q "^Usage: hoist-lcm-spy " || fail "--help"
"$spy" --version | grep -Eq "^hoist-lcm-spy [0-9]+\.[0-9]+\.[0-9]+" || fail "--version"
"$spy" --bogus >/dev/null 2>&1; [ $? -eq 2 ] || fail "an unknown option must exit 2"
"$spy" --lcm-url >/dev/null 2>&1; [ $? -eq 2 ] || fail "--lcm-url without a URL must exit 2"
"$spy" --lcm-url 'bogus://x' >/dev/null 2>&1; [ $? -eq 2 ] || fail "a bad LCM URL must exit 2"
"$spy" --lcm-url 'udpm://239.255.76.67:7667?ttl=abc' >/dev/null 2>&1; [ $? -eq 2 ] || fail "ttl=abc must exit 2"
"$spy" --lcm-url '' >/dev/null 2>&1; [ $? -eq 2 ] || fail "an empty --lcm-url must exit 2"
cp=$("$spy" --print-classpath) || fail "--print-classpath (a jar is missing)"
echo "class path: $cp"
# Without a display: one clear line, no Java HeadlessException trace.
out=$(env -u DISPLAY -u WAYLAND_DISPLAY "$spy" 2>&1); rc=$?
[ $rc -eq 1 ] || fail "without a display: exit $rc (expected 1): $out"
case "$out" in *"hoist-lcm-spy: no display"*) ;; *) fail "without a display: $out" ;; esac
case "$out" in *Exception*) fail "without a display: a Java trace: $out" ;; esac
case "$cp" in *jchart2d*) ;; *) fail "jchart2d.jar is not on the class path" ;; esac
rm -rf "$work" && mkdir -p "$work/classes" || exit 1
javac -nowarn -cp "$cp" -d "$work/classes" "$src/SpyFieldViewTest.java" || fail "javac SpyFieldViewTest"
# Without a display: at least every class the field view needs must load.
cat >"$work/LoadClasses.java" <<'JAVA'
public class LoadClasses {
  public static void main(String[] a) throws Exception {
    for (String c : new String[] {"lcm.spy.Spy", "lcm.spy.ObjectPanel", "lcm.spy.ChartData",
                                  "info.monitorenter.gui.chart.ITrace2D", "info.monitorenter.gui.chart.Chart2D",
                                  "hoist.cage_state_t", "hoist.alarm_t", "hoist.health_t"})
      Class.forName(c, true, LoadClasses.class.getClassLoader());
    System.out.println("ok: lcm-spy, jchart2d and hoist classes load");
  }
}
JAVA
javac -nowarn -cp "$cp" -d "$work/classes" "$work/LoadClasses.java" || fail "javac LoadClasses"
java -Djava.awt.headless=true -cp "$cp:$work/classes" LoadClasses || fail "classes do not load"
if ! command -v xvfb-run >/dev/null 2>&1; then
  echo "SKIP: xvfb-run not installed (package xvfb): the field view was not opened, only the classes loaded"
  exit 77
fi
timeout 120 xvfb-run -a -s "-screen 0 1024x768x24" \
  java -Djava.net.preferIPv4Stack=true -cp "$cp:$work/classes" lcm.spy.SpyFieldViewTest ||
  fail "the HOIST_CAGE field view under Xvfb"
