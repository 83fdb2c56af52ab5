// Decodes every event of an LCM log with the Java classes of the types jar (the classes
// lcm-spy uses) and prints each field flattened as the C++ schema decoder names it:
//   == CHANNEL
//   name=value            numbers and booleans as Java prints them
//   name=s:HEX            strings, as the hex of the bytes they were decoded from
// The channel of each event is the full type name (package.type) to decode it with.
// Usage: java -cp .:lcm.jar:TYPES.jar... JarDecode LOG OUT
import java.io.EOFException;
import java.io.FileOutputStream;
import java.io.PrintStream;
import java.lang.reflect.Array;
import java.lang.reflect.Field;
import java.lang.reflect.Modifier;
import java.nio.charset.StandardCharsets;

public class JarDecode {
  public static void main(String[] args) throws Exception {
    lcm.logging.Log log = new lcm.logging.Log(args[0], "r");
    PrintStream out = new PrintStream(new FileOutputStream(args[1]), false, "UTF-8");
    while (true) {
      lcm.logging.Log.Event event;
      try {
        event = log.readNext();
      } catch (EOFException end) {
        break;
      }
      Class<?> type = Class.forName(event.channel);
      // The generated constructor checks the fingerprint and throws if it does not match.
      Object message = type.getConstructor(byte[].class).newInstance((Object) event.data);
      out.println("== " + event.channel);
      flatten("", message, out);
    }
    out.close();
  }

  static void flatten(String prefix, Object message, PrintStream out) throws Exception {
    for (Field field : message.getClass().getFields()) {
      if (Modifier.isStatic(field.getModifiers())) continue;  // constants, fingerprints
      emit(prefix + field.getName(), field.get(message), out);
    }
  }

  static void emit(String name, Object value, PrintStream out) throws Exception {
    if (value.getClass().isArray()) {
      for (int i = 0; i < Array.getLength(value); i++) {
        emit(name + "[" + i + "]", Array.get(value, i), out);
      }
    } else if (value instanceof lcm.lcm.LCMEncodable) {
      flatten(name + ".", value, out);
    } else if (value instanceof String) {
      // LCM 1.3.1's Java classes turn each string byte into one char (Latin-1), so UTF-8 text
      // from C++ shows as mojibake in lcm-spy; the bytes are intact, and that is checked here.
      StringBuilder hex = new StringBuilder();
      for (byte b : ((String) value).getBytes(StandardCharsets.ISO_8859_1)) {
        hex.append(String.format("%02x", b & 0xff));
      }
      out.println(name + "=s:" + hex);
    } else {
      out.println(name + "=" + value);
    }
  }
}
