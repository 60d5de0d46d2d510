# Run on each file fastddsgen writes (-DFILE=...): two fixes to how fastddsgen 2.x decodes a
# sample from the network, both found by tests/fuzz/fuzz_samples.
#  - A sequence of bounded strings is resized to the length the sample claims before any
#    element is read: a 40-byte sample claiming 8,000,000 names allocated 2 GB. Every such
#    sequence in idl/ is an `Ids` (at most 256): a longer one is refused as a truncated
#    sample is.
#  - The type support catches only NotEnoughMemoryException; fastcdr throws others (a bool
#    byte that is neither 0 nor 1: BadParamException), which would leave Fast DDS's reader
#    thread. Any CDR exception refuses the sample.
file(READ "${FILE}" text)
string(REGEX REPLACE "([ ]*)(m_[a-z_]+)\\.resize\\(sequence_size\\);"
       "\\1if (sequence_size > 256) throw eprosima::fastcdr::exception::NotEnoughMemoryException(\"a sequence longer than its bound of 256\");\n\\1\\2.resize(sequence_size);"
       text "${text}")
string(REPLACE "catch (eprosima::fastcdr::exception::NotEnoughMemoryException& /*exception*/)"
       "catch (eprosima::fastcdr::exception::Exception& /*exception*/)" text "${text}")
file(WRITE "${FILE}" "${text}")
