// Runs lcm-spy (lcm.spy.Spy) in this JVM, prints READY once its window's channel table exists,
// then, when every channel named has a row (or after SECONDS), prints what the table shows, one
// row per line: the columns' values separated by tabs, after a header line. What lcm-spy draws is
// read from its Swing table model, not from pixels (no OCR), so the check is what a person sees
// in the table: each channel and the type lcm-spy decoded it as.
//   java SpyTable SECONDS CHANNEL,CHANNEL,... [lcm-spy arguments...]
import java.awt.Component;
import java.awt.Container;
import java.awt.Frame;
import javax.swing.JTable;
import javax.swing.SwingUtilities;
import javax.swing.table.TableModel;

public class SpyTable {
  public static void main(String[] args) throws Exception {
    final long deadline = System.currentTimeMillis() + (long) (Double.parseDouble(args[0]) * 1000);
    final java.util.List<String> expected = java.util.Arrays.asList(args[1].split(","));
    lcm.spy.Spy.main(java.util.Arrays.copyOfRange(args, 2, args.length));
    JTable table = null;
    while (table == null && System.currentTimeMillis() < deadline) {
      Thread.sleep(100);
      table = onSwingThread(SpyTable::findSpyTable);
    }
    if (table == null) {
      System.out.println("NO_TABLE");
      System.exit(1);
    }
    System.out.println("READY");
    System.out.flush();
    final JTable found = table;
    while (System.currentTimeMillis() < deadline && !onSwingThread(() -> channels(found).containsAll(expected)))
      Thread.sleep(200);
    SwingUtilities.invokeAndWait(() -> {
      TableModel model = found.getModel();
      StringBuilder header = new StringBuilder("COLUMNS");
      for (int c = 0; c < model.getColumnCount(); ++c) header.append('\t').append(model.getColumnName(c));
      System.out.println(header);
      for (int r = 0; r < model.getRowCount(); ++r) {
        StringBuilder row = new StringBuilder("ROW");
        for (int c = 0; c < model.getColumnCount(); ++c) row.append('\t').append(model.getValueAt(r, c));
        System.out.println(row);
      }
    });
    System.out.flush();
    // Leave the window up for the screenshot; the test ends this JVM.
  }

  static <T> T onSwingThread(java.util.function.Supplier<T> supplier) throws Exception {
    java.util.concurrent.atomic.AtomicReference<T> result = new java.util.concurrent.atomic.AtomicReference<>();
    SwingUtilities.invokeAndWait(() -> result.set(supplier.get()));
    return result.get();
  }

  static JTable findSpyTable() {
    for (Frame frame : Frame.getFrames()) {
      JTable table = findTable(frame);
      if (table != null) return table;
    }
    return null;
  }

  // The channels listed (lcm-spy's first column).
  static java.util.Set<String> channels(JTable table) {
    java.util.Set<String> names = new java.util.HashSet<>();
    TableModel model = table.getModel();
    for (int r = 0; r < model.getRowCount(); ++r) names.add(String.valueOf(model.getValueAt(r, 0)));
    return names;
  }

  static JTable findTable(Component component) {
    if (component instanceof JTable) return (JTable) component;
    if (component instanceof Container) {
      for (Component child : ((Container) component).getComponents()) {
        JTable found = findTable(child);
        if (found != null) return found;
      }
    }
    return null;
  }
}
