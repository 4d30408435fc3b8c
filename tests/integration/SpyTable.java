// Runs lcm-spy (lcm.spy.Spy) in this JVM, prints READY once its window's channel table exists,
// then, when every channel named has a row (or after SECONDS), prints what the table shows, one
// row per line: the columns' values separated by tabs, after a header line. What lcm-spy draws is
// read from its Swing table model, not from pixels (no OCR), so the check is what a person sees
// in the table: each channel and the type lcm-spy decoded it as.
// With -Dspy.open=CHANNEL it then double-clicks that channel's row, as a person does to see its
// fields, and prints "VIEWER <title>" for every window then open (lcm-spy opens one per channel).
//   java [-Dspy.open=CHANNEL] SpyTable SECONDS CHANNEL,CHANNEL,... [lcm-spy arguments...]
import java.awt.Component;
import java.awt.Container;
import java.awt.Frame;
import java.awt.Rectangle;
import java.awt.event.MouseEvent;
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
    final String open = System.getProperty("spy.open");
    if (open != null) {
      SwingUtilities.invokeAndWait(() -> doubleClick(found, open));
      Thread.sleep(1500);  // the viewer window opens and draws the next message's fields
      SwingUtilities.invokeAndWait(() -> {
        for (Frame frame : Frame.getFrames()) {
          if (!frame.isShowing()) continue;
          // The field view beside the channel table (it opens over it), so that the picture has both.
          if (frame.getTitle().contains(open)) frame.setLocation(420, 190);
          System.out.println("VIEWER " + frame.getTitle());
        }
      });
      Thread.sleep(500);
      System.out.flush();
    }
    // Leave the window up for the screenshot; the test ends this JVM.
  }

  // The mouse events of a double click on the row showing `channel` (lcm-spy opens its viewer).
  static void doubleClick(JTable table, String channel) {
    for (int row = 0; row < table.getRowCount(); ++row) {
      if (!channel.equals(String.valueOf(table.getValueAt(row, 0)))) continue;
      Rectangle cell = table.getCellRect(row, 0, true);
      int x = cell.x + cell.width / 2, y = cell.y + cell.height / 2;
      long now = System.currentTimeMillis();
      for (int id : new int[] {MouseEvent.MOUSE_PRESSED, MouseEvent.MOUSE_RELEASED, MouseEvent.MOUSE_CLICKED})
        table.dispatchEvent(new MouseEvent(table, id, now, 0, x, y, 2, false, MouseEvent.BUTTON1));
      return;
    }
    System.out.println("NO_ROW " + channel);
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
