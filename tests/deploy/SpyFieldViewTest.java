// Opens lcm-spy's field view of HOIST_CAGE, headless under Xvfb, and fails on
// any exception (the view once crashed with NoClassDefFoundError
// info/monitorenter/gui/chart/ITrace2D when jchart2d was off the class path).
//
// In package lcm.spy to reach Spy's package-private channel table and its
// createViewer(), which is what a double-click on a channel row calls.  Runs
// with hoist-lcm-spy's own class path (hoist-lcm-spy --print-classpath), on
// LCM's in-process memq:// so no network is involved.
package lcm.spy;

import java.awt.Window;
import java.awt.image.BufferedImage;
import java.util.concurrent.atomic.AtomicReference;
import javax.swing.SwingUtilities;

public class SpyFieldViewTest {
  public static void main(String[] args) {
    try {
      run();
    } catch (Throwable e) {  // includes NoClassDefFoundError; never leave the EDT holding the JVM
      System.err.println("FAIL: " + e);
      e.printStackTrace();
      System.exit(1);
    }
  }

  static void run() throws Exception {
    final AtomicReference<Throwable> failure = new AtomicReference<>();
    Thread.setDefaultUncaughtExceptionHandler((t, e) -> {
      failure.compareAndSet(null, e);
      e.printStackTrace();
    });
    final Spy spy = new Spy("memq://");
    hoist.cage_state_t m = new hoist.cage_state_t();
    for (int i = 0; i < 20; ++i) {
      m.utime = System.currentTimeMillis() * 1000;
      m.seq = i;
      m.t = 0.01 * i;
      m.l = 50.0 + 0.05 * i;
      m.y_c = 0.004944 + 1e-5 * i;
      m.theta = 7.242e-4;
      m.lambdas[1] = -31.3;
      spy.lcm.publish("HOIST_CAGE", m);
      Thread.sleep(20);
    }
    Thread.sleep(500);
    final ChannelData cd = spy.channelMap.get("HOIST_CAGE");
    if (cd == null) throw new AssertionError("lcm-spy saw no HOIST_CAGE");
    if (cd.cls == null || !cd.cls.getName().equals("hoist.cage_state_t"))
      throw new AssertionError("HOIST_CAGE not decoded: type " + cd.cls + " (hoist_msgs.jar missing from the class path?)");
    // What a double-click on the HOIST_CAGE row does.
    SwingUtilities.invokeAndWait(() -> spy.createViewer(cd));
    for (int i = 20; i < 40; ++i) {  // the open view follows new messages (and plots them)
      m.seq = i;
      m.t = 0.01 * i;
      spy.lcm.publish("HOIST_CAGE", m);
      Thread.sleep(20);
    }
    Thread.sleep(500);
    final AtomicReference<String> title = new AtomicReference<>("");
    SwingUtilities.invokeAndWait(() -> {
      if (cd.viewerFrame == null || cd.viewer == null) throw new AssertionError("no field view opened");
      title.set(cd.viewerFrame.getTitle());
      // Paint the field view (fields, sparklines) into an image.
      BufferedImage img = new BufferedImage(800, 600, BufferedImage.TYPE_INT_RGB);
      cd.viewerFrame.setSize(800, 600);
      cd.viewerFrame.validate();
      cd.viewerFrame.printAll(img.getGraphics());
    });
    Thread.sleep(300);
    if (failure.get() != null) {
      System.err.println("FAIL: exception while opening the HOIST_CAGE field view: " + failure.get());
      System.exit(1);
    }
    System.out.println("ok: HOIST_CAGE field view '" + title.get() + "' opened and painted (type " + cd.cls.getName()
                       + ", " + cd.nreceived + " messages)");
    for (Window w : Window.getWindows()) w.dispose();
    System.exit(0);
  }
}
